"""Readers and writers of every file format: URDF, SDF, xacro, STL, ROS packages, output files.

Everything here turns bytes on disk into the intermediate model (`reedtool.model`) or
writes results back; nothing here computes physics or judges a model.
"""
