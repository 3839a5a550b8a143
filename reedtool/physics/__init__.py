"""What is computed on the model: kinematics, mass properties, meshes, rotors, allocation, trim.

Pure functions of a `reedtool.model.Robot` (or arrays); they read files only through
`reedtool.io` and never report or print.
"""
