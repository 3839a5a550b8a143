"""The controller side: rotor tables a flight controller is told (RotorS YAML, gz-sim
velocity control), read with source lines so checks can compare them with the model.
"""
