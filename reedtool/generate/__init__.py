"""`new-package` and `import-stl --package`: the frame catalogue, the package's parameters,
the CAD body on its motor mounts, autopilot files, and the template tree rendered."""
