"""Where a name points: `$(find pkg)` and `package://`, `model://` and include URIs, and
`name:=value` arguments, resolved without ROS or Gazebo installed; and where a file
reference may point (references.py)."""
