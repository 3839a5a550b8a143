"""`new-package` as one call: the package's parameters (generate.package_spec) and, with
--mesh, its CAD body (generate.cad_body) rendered from the template sets into a new
directory, all or nothing (generate.render), with the autopilot's files on request.
The caller prints the summary (report.new_package_text).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path, PurePosixPath


@dataclass
class NewPackageResult:
    target: Path
    files: list[PurePosixPath]
    backup: Path | None
    context: dict
    mesh: object | None = None     # the CAD body (generate.cad_body.CadBody)
    model: PurePosixPath | None = None   # the file to expand, validate and hover-test


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
    return NewPackageResult(target, sorted(f.path for f in files), backup, context, body,
                            model_path(spec))
