"""A model for gz-sim: migrate's port plan (links, joints, every Classic plugin family and
sensor mapped or dropped with its reason), the SDF and URDF it is written as, and the gz
contracts of PX4 and ArduPilot (also used by `new-package --sim gz`)."""
