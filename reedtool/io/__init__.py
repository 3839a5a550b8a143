"""Readers and writers of every file format, each reader beside its writer: URDF
(urdf.py / urdf_write.py / urdf_edit.py), SDF (sdf.py / sdf_write.py), xacro, meshes
(one loader table in meshes.py), launch files, guarded file reads and writes.

Everything here turns bytes on disk into the intermediate model (`reedtool.model`) or
writes results back; nothing here computes physics or judges a model. Where a name or a
reference points is resolved below, in `reedtool.resolve`.
"""
