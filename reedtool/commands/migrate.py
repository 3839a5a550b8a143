"""`reedtool migrate`: port a Gazebo Classic multirotor to Gazebo Sim, and prove the port
flies the same.

Exit 0 when the port reads back equal to the original (numbers to 1e-9 relative), 1 with
the differences listed, 2 on input errors (an existing output directory without --force).
"""

from __future__ import annotations

from pathlib import Path

import click

from reedtool.commands.params import model_inputs, one_model_request


@click.command(name="migrate")
@model_inputs()
@click.option("--to", "to", type=click.Choice(["gz"]), required=True,
              help="Target simulator: gz (Gazebo Sim, Harmonic and later).")
@click.option("-o", "--output-dir", type=click.Path(path_type=Path, file_okay=False),
              required=True, help="Directory to create the model directory NAME in.")
@click.option("--name", default=None,
              help="Model (and directory) name (default: the robot's name).")
@click.option("--urdf", is_flag=True,
              help="Also write the ROS 2 form, urdf/NAME.urdf: the links and joints as URDF "
                   "with the gz systems in <gazebo> elements (robot_state_publisher, "
                   "ros_gz_sim create).")
@click.option("--velocity-control", is_flag=True,
              help="Add gz's MulticopterVelocityControl (twist commands), gains derived as "
                   "new-package --sim gz derives them.")
@click.option("--autopilot", type=click.Choice(["px4", "ardupilot"]), default=None,
              help="Also write the autopilot's files: a PX4 gz airframe (px4/), or an "
                   "ArduPilot .parm (ardupilot/) with the ArduPilotPlugin and LiftDrag blades "
                   "driving the rotors in place of the motor models.")
@click.option("--copy-outside-files", is_flag=True,
              help="Also copy mesh files that lie outside the model's packages (an absolute "
                   "file:// URI, a path climbing out with ..) into the port. Without it they "
                   "are referenced where they are and listed in the report.")
@click.option("--force", is_flag=True,
              help="Write into an existing output directory, replacing the files migrate "
                   "writes (the old directory is kept as NAME.bak).")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="Output format.")
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None, launch_file: Path | None, to: str, output_dir: Path,
            name: str | None, urdf: bool, velocity_control: bool, autopilot: str | None,
            copy_outside_files: bool, force: bool, fmt: str) -> int:
    """Port MODEL to a Gazebo Sim model directory OUTPUT_DIR/NAME, then read it back and
    compare it with the original: links, joints, masses, inertias, poses, rotors, hover
    trim, hover-test verdict and validate's findings.

    MODEL is a .urdf, .xacro (.urdf.xacro), .gazebo, or Classic .sdf or .world file, or a
    directory, glob or ROS package holding one model; NAME:=VALUE words are its xacro
    arguments.
    """
    from reedtool.workflows.migration import MigrateRequest, migrate

    model, request = one_model_request("migrate", inputs, package_paths, model_name,
                                       launch_file)
    result = migrate(MigrateRequest(model, output_dir, request, name, velocity_control,
                                    autopilot, force, urdf,
                                    copy_outside_files=copy_outside_files))
    from reedtool.report.migrate_text import render_json, render_text

    click.echo(render_json(result) if fmt == "json" else render_text(result))
    return 0 if result.proof.equal else 1
