"""`reedtool new-package`: scaffold a ROS package that expands, validates and hovers first try."""

from __future__ import annotations

from pathlib import Path

import click

from reedtool.generate.airframes import FRAMES


@click.command(name="new-package")
@click.argument("name")
@click.option("--frame", type=click.Choice(list(FRAMES)), default=None,
              help="Vehicle layout (default: the spec's `frame`, else quad-x).")
@click.option("--ros", type=click.Choice(["1", "2"]), default=None,
              help="ROS 1 (catkin) or ROS 2 (ament_cmake) (default: the spec's, else 1).")
@click.option("--sim", type=click.Choice(["gz", "classic"]), default=None,
              help="Multirotor simulator: gz (Gazebo Sim, Harmonic+; ROS 2 only) or classic "
                   "(Gazebo classic + RotorS). Default: the spec's `sim`, else gz for ROS 2 "
                   "multirotors, classic otherwise.")
@click.option("--spec", "spec_file", type=click.Path(path_type=Path, dir_okay=False),
              help="YAML file of parameters (see docs/new-package.md); flags override it.")
@click.option("--mass", metavar="KG", help="Body mass, e.g. 1.5 or '1500 g'.")
@click.option("--arm-length", metavar="M",
              help="Centre to rotor axis (quad-x: x and y offset of each rotor), e.g. 0.18738.")
@click.option("--mesh", type=click.Path(path_type=Path, dir_okay=False), metavar="BODY.stl",
              help="Body mesh; its shape gives the body inertia.")
@click.option("--mesh-units", default="auto", show_default=True,
              type=click.Choice(["auto", "mm", "cm", "m", "in"]),
              help="Units of the mesh. auto judges by its size, --mass (density) and "
                   "--arm-length, and refuses naming the choices when more than one fits.")
@click.option("--mesh-frame", default=None,
              help="Axes the mesh was exported in (flu, ned, frd, y-up, ...). Default: FLU, "
                   "unless the mesh's extents say it stands on another axis (then say which).")
@click.option("--center", "center", default=None, metavar="origin|com|mounts|X,Y,Z",
              help="With --mesh: the point the rotor pattern is centred on, in the CAD frame "
                   "(FLU): the CAD origin (default with --arm-length), the body's COM, the "
                   "motor mounts' centre, or x,y,z with a unit ('15.2,0,0 mm'). Without "
                   "--center and --arm-length the rotors go on the mesh's motor mounts.")
@click.option("--motor", metavar="KV|NAME",
              help="Motor KV (rpm/V), e.g. 920, or a named motor (docs/new-package.md); with "
                   "--prop and --battery it derives the motor constants.")
@click.option("--prop", metavar="DxP",
              help="Propeller diameter x pitch in inches, e.g. 10x4.7 (UIUC-measured "
                   "static coefficients).")
@click.option("--battery", metavar="NS", help="LiPo cells in series, e.g. 4S.")
@click.option("-o", "--output-dir", type=click.Path(path_type=Path, file_okay=False),
              default=Path("."), show_default=True,
              help="Directory to create the package directory NAME in.")
@click.option("--force", is_flag=True,
              help="Regenerate into an existing package; the old tree is kept as NAME.bak.")
@click.option("--autopilot", type=click.Choice(["px4", "ardupilot"]), default=None,
              help="Also write the autopilot's rotor table for this model: a PX4 gz airframe "
                   "(px4/) or an ArduPilot .parm (ardupilot/).")
def command(name, frame, ros, sim, spec_file, mass, arm_length, mesh, mesh_units, mesh_frame,
            output_dir, force, autopilot=None, center=None, motor=None, prop=None,
            battery=None) -> int:
    """Create the ROS package NAME for a multirotor or ground robot.

    Masses and inertias are computed from the geometry; a multirotor (gz-sim
    MulticopterMotorModel systems, or the RotorS macro interface with --sim classic) passes
    `reedtool validate` and `hover-test` as generated.
    """
    from reedtool.generate.package_spec import build_spec
    from reedtool.report.new_package_text import summary_lines
    from reedtool.workflows.new_package import new_package

    spec = build_spec(name, frame=frame, ros=int(ros) if ros else None, spec_file=spec_file,
                      flags={"mass": mass, "arm_length": arm_length}, mesh=mesh, sim=sim,
                      drive={"motor": motor, "prop": prop, "battery": battery})
    result = new_package(spec, output_dir, force=force, mesh_units=mesh_units,
                         mesh_frame=mesh_frame, autopilot=autopilot, center=center)
    for line in summary_lines(result, spec):
        click.echo(line)
    return 0
