"""Where a name points: `$(find pkg)` and `package://`, `model://` and include URIs, and
`name:=value` arguments, resolved without ROS or Gazebo installed."""
