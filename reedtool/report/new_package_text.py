"""`new-package`'s summary: what was created, the CAD body as import-stl words it, the
rotors and propulsion, and the commands to run next. Formats workflows.new_package's
result; computes nothing."""

from __future__ import annotations


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


def summary_lines(result, spec) -> list[str]:
    """`result`: a workflows.new_package.NewPackageResult; `spec`: what was built."""
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
    model = result.model
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
