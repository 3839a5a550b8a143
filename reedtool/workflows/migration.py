"""`migrate`: a Gazebo Classic multirotor -> a Gazebo Sim model directory, and its proof.

One call, `migrate(request)`: load the original with its arguments as every command does
(workflows.assemble.load_robot_for: configuration, --launch, name:=value), plan the port
(port.gz_port), add what needs the whole vehicle (MulticopterVelocityControl gains,
the PX4 airframe), stage the directory beside the target (port.sdf_writer,
generate.render.staged_tree), read model.sdf back there with reedtool's SDF reader and
compare it with the original, both assembled as hover-test assembles them
(workflows.port_proof), and only then rename it into place: a migrate that fails leaves
nothing on disk.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

import numpy as np

from reedtool.workflows.robots import ModelRequest
from reedtool.errors import ReedtoolError
from reedtool.port.gz_port import (
    VELOCITY_CONTROL_SYSTEM,
    Element,
    GzPort,
    PortOptions,
    PortRow,
    plan_port,
)

NAME_PATTERN = re.compile(r"^[A-Za-z][A-Za-z0-9_-]*$")


@dataclass
class MigrateRequest:
    model: Path
    output_dir: Path
    models: ModelRequest = field(default_factory=ModelRequest)   # arguments, --launch, ...
    name: str | None = None
    velocity_control: bool = False
    autopilot: str | None = None
    force: bool = False
    urdf: bool = False                      # also the ROS 2 form, urdf/<name>.urdf
    hover_config: object | None = None      # sim.HoverConfig; None: hover-test's defaults
    fly: bool = True
    copy_outside_files: bool = False        # copy meshes from outside the model's packages


@dataclass
class MigrateResult:
    target: Path
    files: list[PurePosixPath]
    rows: list[PortRow]
    proof: object                            # workflows.port_proof.Proof
    port: GzPort
    source: str

    def to_dict(self) -> dict:
        return {"target": str(self.target), "files": [str(f) for f in self.files],
                "elements": [row.to_dict() for row in self.rows],
                "proof": self.proof.to_dict()}


def port_name(robot_name: str, given: str | None) -> str:
    """The model directory name: --name, else the robot's name made a valid one."""
    if given is not None:
        if not NAME_PATTERN.match(given):
            raise ReedtoolError(f"bad --name '{given}'",
                                hint="use letters, digits, '_' and '-', starting with a letter")
        return given
    name = re.sub(r"[^A-Za-z0-9_-]+", "_", robot_name).strip("_") or "model"
    return name if name[0].isalpha() else f"model_{name}"


def migrate(request: MigrateRequest) -> MigrateResult:
    from reedtool.workflows.assemble import load_robot_for
    from reedtool.io.fileio import note_input
    from reedtool.generate.render import RenderedFile, check_target, staged_tree

    note_input(request.model)
    original, _mappings = load_robot_for(request.model, request.models)
    name = port_name(original.name, request.name)
    target = Path(request.output_dir) / name
    check_target(target, request.force,
                 force_does="replace the files migrate writes (other files are kept; the "
                            "old directory is kept whole as NAME.bak)")
    source = str(request.model)

    port = plan_port(original, name, PortOptions(request.velocity_control, request.autopilot))
    port.outside_files = outside_files(port, request.model)
    port.copy_outside_files = request.copy_outside_files
    port.target_dir = target
    from reedtool.port.sdf_writer import WrittenFile, port_files

    contract = None
    extra_plugins, extra_files = [], []
    if request.autopilot == "px4":
        # First: the root's new name is the one every later part refers to.
        from reedtool.port.px4_gz_contract import apply_px4_contract

        contract = apply_px4_contract(port)
    if request.velocity_control:
        extra_plugins.append(velocity_control(original, port))
    if request.autopilot == "px4":
        from reedtool.port.px4_gz_contract import airframe_path, readme_text

        extra_files.append(WrittenFile(airframe_path(name),
                                       px4_airframe(original, name).encode("utf-8")))
        extra_files.append(WrittenFile(PurePosixPath("README.md"),
                                       readme_text(name, "migrate").encode("utf-8")))
    elif request.autopilot == "ardupilot":
        from reedtool.port.ardupilot_gz import ardupilot_port

        plugins, parm = ardupilot_port(original, port)
        extra_plugins += plugins
        extra_files.append(WrittenFile(PurePosixPath("ardupilot", f"{name}.parm"),
                                       parm.encode("utf-8")))
    if request.urdf:
        from reedtool.port.sdf_writer import mesh_targets
        from reedtool.port.urdf_writer import ros2_urdf

        extra_files.append(WrittenFile(PurePosixPath("urdf", f"{name}.urdf"), ros2_urdf(
            original, port, mesh_targets(port), extra_plugins)))
    written, mesh_rows = port_files(port, source, extra_plugins, extra_files)
    model_file = PurePosixPath("model.sdf")
    if contract is not None:
        written.files = _px4_layout(written.files, name)
        model_file = PurePosixPath("models", name, "model.sdf")
    rows = [*port.rows, *mesh_rows]
    if request.velocity_control:
        rows.append(PortRow(original.loc, "velocity controller (--velocity-control)", "mapped",
                            f"plugin {VELOCITY_CONTROL_SYSTEM[0]}",
                            "gains: RotorS' firefly Lee gains scaled by this model's mass and "
                            "inertia, as new-package --sim gz derives them; one <rotor> per "
                            "motor model with its constants and direction",
                            target=extra_plugins[0]))
    for row in rows:
        line = written.lines.get(id(row.target)) if row.target is not None else \
            written.lines.get(row.target_key) if row.target_key is not None else None
        if line is not None:
            row.output = f"{model_file}:{line} {row.output}"
    # All or nothing: the port is written into a hidden directory beside the target and
    # read back there; only a port that could be read back is renamed into place.
    files = [RenderedFile(f.path, f.data, 0o644) for f in written.files]
    with staged_tree(target, files, force=request.force) as staged:
        try:
            proof = prove(original, staged.path.joinpath(*model_file.parts), port, request,
                          contract)
        except ReedtoolError as exc:
            raise ReedtoolError(
                f"migrate could not read back the port it wrote ({exc.message}); nothing "
                "was written", file=request.model,
                hint="this is a reedtool bug: please report it with the model") from exc
        _name_the_target(proof, staged.path, target)
    return MigrateResult(target, sorted(f.path for f in written.files), rows, proof, port,
                         source)


def _px4_layout(files, name: str):
    """The flat port's files in PX4-gazebo-models' layout (models/NAME, worlds/NAME.sdf:
    PX4's world, named as its file, without the vehicle PX4 spawns itself)."""
    from reedtool.port.px4_gz_contract import px4_layout, px4_world_sdf
    from reedtool.port.sdf_writer import WrittenFile

    out = []
    for file in files:
        if file.path == PurePosixPath("worlds", f"{name}.sdf"):
            out.append(WrittenFile(file.path, px4_world_sdf(name)))
        elif file.path.parts[0] in ("airframes", "README.md"):
            out.append(file)
        else:
            out.append(WrittenFile(px4_layout(name, file.path), file.data))
    return out


def prove(original, model_sdf: Path, port: GzPort, request: MigrateRequest, contract=None):
    """Read the written port back and compare it with the original.

    validate's rules run on both with the original's selection and severities (its
    configuration, --select/--ignore), before suppressions: an inline suppression comment
    stays in the source, so comparing after them would count it as a finding introduced.
    """
    from reedtool.workflows.assemble import load_robot_for
    from reedtool.workflows.port_proof import (
        Proof,
        compare_findings,
        compare_sensors,
        compare_structure,
        compare_vehicle,
    )
    from reedtool.workflows.validation import selection_for
    from reedtool.checks.runner import run_checks
    from reedtool.config import load_config
    from reedtool.sim import HoverConfig

    models = request.models
    ported, _ = load_robot_for(model_sdf, ModelRequest(package_paths=list(models.package_paths)))
    selection = selection_for(load_config(request.model), models.select, models.ignore)
    proof = Proof()
    fold = _fold_map(original, port, contract)
    compare_structure(original, ported, fold, proof)
    compare_sensors(original, ported, fold, proof, port.added_sensors, port.moved_sensors)
    compare_vehicle(original, ported, proof, request.hover_config or HoverConfig(),
                    fly=request.fly)
    # A macro call writes many elements at one line: the macro line tells them apart.
    dropped = [(loc.file, loc.line, loc.macro) for row in port.rows
               if row.action in ("dropped", "unknown") for loc in (row.source, *row.covers)]
    resolved = {"S169": "--copy-outside-files copied the file into it"} \
        if port.copy_outside_files else {}
    compare_findings(run_checks(original, selection), run_checks(ported, selection), proof,
                     dropped, resolved)
    return proof


def _name_the_target(proof, staged: Path, target: Path) -> None:
    """The proof read the port in its staging directory; its messages name the target."""
    def rename(value):
        if isinstance(value, str):
            return value.replace(str(staged), str(target))
        if isinstance(value, list):
            return [rename(v) for v in value]
        if isinstance(value, dict):
            return {k: rename(v) for k, v in value.items()}
        return value

    proof.notes = rename(proof.notes)
    proof.side_by_side["findings"] = rename(proof.side_by_side.get("findings", {}))


def outside_files(port: GzPort, model: Path) -> dict[str, str]:
    """Mesh URI -> why its file lies outside the model's packages (io.meshes)."""
    from reedtool.resolve.references import outside_reason

    default_root = Path(model) if Path(model).is_dir() else Path(model).parent
    out = {}
    for link in port.links:
        for _T, shape in [*link.visuals, *link.collisions]:
            mesh = shape.geometry
            if getattr(mesh, "uri", None) in port.meshes and mesh.uri not in out:
                reason = outside_reason(mesh.uri, mesh.path, shape.loc.file, default_root)
                if reason is not None:
                    out[mesh.uri] = reason
    return out


def _fold_map(original, port: GzPort, contract=None) -> dict:
    """Every original link -> (port link, T_portlink_link), from the plan's frames (and the
    root PX4's contract renamed to base_link)."""
    out = {link.name: (link.name, np.eye(4)) for link in port.links}
    if contract is not None and contract.renamed_root is not None:
        out[contract.renamed_root] = (port.links[0].name, np.eye(4))
    for frame in port.frames:
        out[frame.name] = (frame.attached_to, frame.T_link_frame)
    return out


# ------------------------------------------------------------ whole-vehicle parts

def velocity_control(robot, port: GzPort) -> Element:
    """gz's MulticopterVelocityControl for the model's lift rotors, gains as new-package
    --sim gz derives them (generate.package_spec.scaled_lee_gains)."""
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio
    from reedtool.physics.rotors import discover_rotors, lift_rotors
    from reedtool.generate.package_spec import scaled_lee_gains

    props = whole_robot_pinocchio(robot)
    gains = scaled_lee_gains(props.mass_kg, props.inertia_kg_m2)
    out = Element("plugin", {"filename": VELOCITY_CONTROL_SYSTEM[0],
                             "name": VELOCITY_CONTROL_SYSTEM[1]})
    out.add("robotNamespace", port.namespace)
    out.add("commandSubTopic", "gazebo/command/twist")
    out.add("enableSubTopic", "enable")
    out.add("comLinkName", port.links[0].name)
    out.add("velocityGain", " ".join(gains["velocity_gain"]))
    out.add("attitudeGain", " ".join(gains["attitude_gain"]))
    out.add("angularRateGain", " ".join(gains["angular_rate_gain"]))
    out.add("maximumLinearAcceleration", "2 2 2")
    table = out.add("rotorConfiguration")
    rotors = sorted(lift_rotors(discover_rotors(robot)),
                    key=lambda r: (r.motor_number is None, r.motor_number or 0))
    for rotor in rotors:
        entry = table.add("rotor")
        entry.add("jointName", rotor.joint)
        entry.add("forceConstant", rotor.plugin.param("motorConstant") or repr(rotor.motor_constant))
        entry.add("momentConstant", rotor.plugin.param("momentConstant")
                  or repr(rotor.moment_constant))
        entry.add("direction", str(rotor.turning_sign))
    return out


def px4_airframe(robot, name: str) -> str:
    """The PX4 gz airframe of the model's lift rotors, through flightstack.px4's writer:
    CA rotors about the COM, SIM_GZ_EC_FUNC per actuator_number, MPC_THR_HOVER from the
    trim."""
    from reedtool.flightstack.px4 import RotorSpec, px4_airframe_text, px4_hover_throttle
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio
    from reedtool.physics.rotors import discover_rotors, lift_rotors
    from reedtool.physics.trim import solve_trim

    props = whole_robot_pinocchio(robot)
    rotors = lift_rotors(discover_rotors(robot))
    missing = [r.name for r in rotors if r.motor_number is None]
    if missing or not rotors:
        raise ReedtoolError(f"--autopilot px4 needs a motor number on every rotor "
                            f"({', '.join(missing) or 'no rotors'})", file=robot.source_file,
                            hint="`reedtool validate` lists the rotors and their numbers")
    specs = [RotorSpec(r.motor_number, r.position_m - props.com_m, r.turning_sign,
                       r.moment_constant, r.max_rot_velocity_rad_s, r.axis) for r in rotors]
    trim = solve_trim(props.mass_kg, props.com_m, rotors)
    throttle = px4_hover_throttle(trim.omega_rad_s, [r.max_rot_velocity_rad_s for r in rotors]) \
        if trim.feasible else 0.5
    return px4_airframe_text(name, specs, hover_throttle=throttle, world=name, tool="migrate")
