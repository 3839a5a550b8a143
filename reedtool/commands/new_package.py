"""`reedtool new-package`: scaffold a ROS package that expands, validates and hovers first try."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path, PurePosixPath

import click

from reedtool.generate.airframes import FRAMES


@dataclass
class NewPackageResult:
    target: Path
    files: list[PurePosixPath]
    backup: Path | None
    context: dict
    mesh: object | None = None     # the CAD body (generate.cad_body.CadBody)


def template_sets(kind: str, ros: int, sim: str = "classic") -> list[str]:
    """Later sets override files of earlier ones with the same output path.

    A gz-sim package shares nothing with the RotorS (`common/<kind>`, `ros2/<kind>`) sets:
    its own set `ros2/gz/<kind>` replaces them, and overrides package.xml, CMakeLists.txt
    and README.md of the `any` sets.
    """
    if sim == "gz":
        return ["common/any", f"ros{ros}/any", f"ros{ros}/gz/{kind}"]
    return ["common/any", f"common/{kind}", f"ros{ros}/any", f"ros{ros}/{kind}"]


def model_path(spec) -> PurePosixPath:
    """The file to expand, validate and hover-test in a generated package."""
    if spec.kind == "multirotor" and spec.sim == "classic":
        return PurePosixPath("urdf", "mav_generic_odometry_sensor.gazebo")
    return PurePosixPath("urdf", f"{spec.name}.urdf.xacro")


def mesh_lines(body, spec) -> list[str]:
    """What new-package assumed about the body mesh, as import-stl says it, and where the
    CAD body put the COM and the rotors."""
    from reedtool.physics.mesh_import import assumption_lines
    from reedtool.generate.cad_body import cad_lines

    imported = body.imported
    size = imported.size_m
    return ([f"body mesh {imported.source}: {imported.file_format}"]
            + [f"  {line}" for line in assumption_lines(imported)]
            + [f"  note: {note}" for note in imported.notes]
            + [f"  size: {size[0]:.4g} x {size[1]:.4g} x {size[2]:.4g} m (x, y, z in FLU)"]
            + cad_lines(body, spec))


def new_package(spec, output_dir: Path, *, force: bool = False, mesh_units: str = "auto",
                mesh_frame: str | None = None, autopilot: str | None = None,
                center: str | None = None) -> NewPackageResult:
    """Render the package for `spec` into output_dir/spec.name, all or nothing.

    `autopilot` ('px4' | 'ardupilot') adds the autopilot's rotor table, written from the
    same frame as the model (reedtool.generate.autopilot).
    """
    from reedtool.generate.autopilot import autopilot_context, autopilot_files, prepare_spec
    from reedtool.generate.render import RenderedFile, check_target, render_tree, write_tree

    spec = prepare_spec(spec, autopilot)

    target = Path(output_dir) / spec.name
    check_target(target.absolute(), force)   # fail before any expensive work
    body_props = mesh_data = body = None
    if spec.mesh is not None:
        from reedtool.io.stl import stl_bytes
        from reedtool.generate.cad_body import load_cad_body

        body = load_cad_body(spec, units=mesh_units, frame=mesh_frame, centre=center)
        body_props = body.props
        mesh_data = stl_bytes(body.imported.triangles_m,
                              header=f"reedtool body of {spec.name}: metres, FLU, CAD origin")
    elif center is not None:
        from reedtool.errors import ReedtoolError

        raise ReedtoolError("--center places rotors on a CAD body: it needs --mesh",
                            hint="drop --center, or pass the body with --mesh")
    from reedtool.generate.package_spec import template_context

    context = template_context(spec, body_props)
    context.update(autopilot_context(spec, autopilot))
    files = render_tree(template_sets(spec.kind, spec.ros, spec.sim), context)
    if mesh_data is not None:
        files.append(RenderedFile(PurePosixPath("meshes", context["mesh_file"]), mesh_data, 0o644))
    files += autopilot_files(spec, autopilot, files)
    backup = write_tree(target, files, force=force)
    return NewPackageResult(target, sorted(f.path for f in files), backup, context, body)


def _summary(result: NewPackageResult, spec) -> list[str]:
    ctx = result.context
    sim = ", gz-sim" if spec.sim == "gz" else ""
    lines = [f"created {result.target} ({len(result.files)} files, ROS {spec.ros}{sim}, "
             f"{spec.frame.title})"]
    if result.backup is not None:
        lines.append(f"previous contents kept in {result.backup}")
    if result.mesh is not None:
        lines.extend(mesh_lines(result.mesh, spec))
    if spec.kind == "multirotor":
        lines.append(f"mass {ctx['p']['mass']} kg body, {ctx['total_mass_kg']} kg total; "
                     f"max thrust / weight {ctx['thrust_to_weight']}")
        for r in ctx["rotors"]:
            lines.append(f"  motor {r['motor_number']}  {r['suffix']:<20} "
                         f"({', '.join(r['position_m'])}) m  {r['direction']}")
        from reedtool.generate.package_spec import propulsion_lines

        lines.extend(propulsion_lines(spec))
    else:
        lines.append(f"mass {ctx['p']['mass']} kg body, {ctx['total_mass_kg']} kg total; "
                     f"{len(ctx['wheels'])} wheels, {ctx['drive'].replace('_', '-')} on cmd_vel")
    model = model_path(spec)
    autopilot = next((f for f in result.files if f.parts[0] == "ardupilot" or (
        f.parts[0] == "px4" and ("airframes" in f.parts or f.name.startswith("airframe")))), None)
    option = {"px4": "--airframe", "ardupilot": "--autopilot-params"}
    check = f" {option[autopilot.parts[0]]} {result.target / autopilot}" if autopilot else ""
    lines.append("next:")
    lines.append(f"  reedtool validate {result.target / model}{check}")
    if spec.kind == "multirotor":
        lines.append(f"  reedtool hover-test {result.target / model}")
    if spec.sim == "gz":
        lines.append(f"  ros2 launch {spec.name} {spec.name}.launch.py   (after colcon build)")
    if any(f.parts[:2] == ("px4", "README.md") for f in result.files):
        lines.append(f"  PX4 SITL: {result.target / 'px4' / 'README.md'}")
    elif any(f.parts[0] == "ardupilot" for f in result.files):
        lines.append(f"  ArduPilot SITL: {result.target / 'README.md'} (sim_vehicle.py -f JSON)")
    return lines


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

    spec = build_spec(name, frame=frame, ros=int(ros) if ros else None, spec_file=spec_file,
                      flags={"mass": mass, "arm_length": arm_length}, mesh=mesh, sim=sim,
                      drive={"motor": motor, "prop": prop, "battery": battery})
    result = new_package(spec, output_dir, force=force, mesh_units=mesh_units,
                         mesh_frame=mesh_frame, autopilot=autopilot, center=center)
    for line in _summary(result, spec):
        click.echo(line)
    return 0
