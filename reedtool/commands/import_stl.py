"""`reedtool import-stl`: a CAD STL into a package, in metres and FLU, with its inertia."""

from __future__ import annotations

import sys
from pathlib import Path

import click


# A large mesh (about 200,000 binary triangles) gets a progress bar.
PROGRESS_MIN_BYTES = 10_000_000
STAGES = ("reading", "checking", "transforming", "mass properties", "collision mesh", "writing")


class _StageBar:
    """Advances a click progress bar one stage at a time."""

    def __init__(self, bar):
        self.bar = bar

    def __call__(self, stage: str) -> None:
        self.bar.label = f"import-stl: {stage}"
        if stage != STAGES[0]:
            self.bar.update(1)


@click.command("import-stl")
@click.argument("mesh", type=click.Path(path_type=Path, dir_okay=False))
@click.option("--package", "package_dir", required=True, metavar="DIR",
              type=click.Path(path_type=Path),
              help="ROS package directory (with package.xml); the mesh goes to DIR/meshes/.")
@click.option("--name", default=None, help="Output name (default: the mesh file's stem).")
@click.option("--units", default="auto", show_default=True,
              type=click.Choice(["auto", "mm", "cm", "m", "in"]),
              help="Units of the STL; auto judges by the size and the mass (density), "
                   "says why, and refuses naming the choices when more than one unit fits.")
@click.option("--from-frame", default="auto", show_default=True, metavar="FRAME",
              help="Axes of the STL: ned, frd, flu, enu, nwu, y-up, z-up, or x/y/z letters "
                   "from f/b, l/r, u/d (e.g. luf). auto: FLU, unless the mesh's extents say "
                   "it stands on another axis (then it is refused, naming the choices).")
@click.option("--mass", "mass_kg", type=float, default=None,
              help="Mass of the part [kg] (into a package new-package wrote: default the "
                   "model's body mass).")
@click.option("--density", "density_kg_m3", type=float, default=None,
              help="Density [kg/m^3] (default 1000 when neither --mass nor --density is given).")
@click.option("--recenter", default="none", show_default=True,
              type=click.Choice(["none", "com", "bbox"]),
              help="Move the mesh origin to its centre of mass or bounding-box centre.")
@click.option("--collision", default="same", show_default=True, metavar="hull|simplify:N|same",
              help="Collision mesh: convex hull, decimated to N faces, or the visual mesh.")
@click.option("--snippet", "snippet_file", type=click.Path(path_type=Path, dir_okay=False),
              default=None, help="Write the URDF/xacro snippet here instead of printing it.")
@click.option("--force", is_flag=True, help="Overwrite existing output files.")
@click.option("--set-body", is_flag=True,
              help="Make the mesh the body of the package's model (a package new-package "
                   "wrote): set mesh_file, body_com_xyz, body_inertia (and mass, with "
                   "--mass or --density) in its xacro file, keeping a numbered backup. "
                   "Without it those lines are printed.")
def command(mesh, package_dir, name, units, from_frame, mass_kg, density_kg_m3, recenter,
            collision, snippet_file, force, set_body=False) -> int:
    """Import a CAD STL into a package: metres, FLU axes, inertia about the COM.

    Writes DIR/meshes/NAME.stl (binary, metres, FLU), optionally NAME_collision.stl, and
    prints the <link> snippet (visual, collision and <inertial>) to paste into a URDF or
    xacro; into a package new-package wrote, also the lines that make the mesh the model's
    body (--set-body writes them). Existing files are never overwritten without --force.
    """
    from reedtool.report.import_text import report_lines
    from reedtool.workflows.import_mesh import run_import

    # Progress is for a person watching a terminal; in a pipe it is one more stderr line.
    big = (sys.stderr.isatty() and mesh.is_file()
           and mesh.stat().st_size >= PROGRESS_MIN_BYTES)
    kwargs = dict(name=name, units=units, from_frame=from_frame, mass_kg=mass_kg,
                  density_kg_m3=density_kg_m3, recenter=recenter, collision=collision,
                  snippet_file=snippet_file, force=force, set_body=set_body)
    if big:
        with click.progressbar(length=len(STAGES) - 1, label="import-stl", file=sys.stderr) as bar:
            outcome = run_import(mesh, package_dir, progress=_StageBar(bar), **kwargs)
            bar.update(1)
    else:
        outcome = run_import(mesh, package_dir, **kwargs)
    for line in report_lines(outcome):
        click.echo(line)
    if snippet_file is not None:
        click.echo(f"wrote {snippet_file} (URDF/xacro snippet)")
    else:
        click.echo("")
        click.echo(outcome.snippet, nl=False)
    return 0
