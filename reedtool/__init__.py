"""reedtool: validate, trim and package multirotor models for ROS/Gazebo without ROS."""

__version__ = "0.2.0"
