"""`reedtool migrate`: an independent reading of every port by Drake, and the speed.

Run on demand (needs `pip install drake`; its wheel took 85 s to install here, over the
one minute the test extra allows, so this is a script and not a test):

    python benchmarks/migrate_drake.py [--repeats 3]

For each fixture the migrate tests use (RotorS firefly hex, hummingbird "+" quad,
pelican, Neo-style tilted hex, PX4-classic iris, the seed quad from its xacro with its
arguments), port it, strip what Drake refuses and Gazebo only warns about (plugins,
sensors, mesh geometry: DESIGN.md), parse the port with Drake (libsdformat inside) and
compare with reedtool's reading of the ORIGINAL: total mass, COM and every link's pose.
Relative tolerance 1e-9: both read the same decimal text; only summation order differs.

Speed (issue 21: "porting the seed quad and flying the port with hover-test takes
seconds"): the median of migrate on the seed quad and of hover-test on its port, with
`validate` of the seed quad measured in the same run as the yardstick.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from click.testing import CliRunner
from lxml import etree

from reedtool.cli import cli
from reedtool.io.fileio import reset_inputs
from reedtool.io.loader import load_robot
from reedtool.physics.kinematics import link_poses
from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT / "tests" / "fixtures"
SEED = FIXTURES / "seed000" / "reed_gazebo" / "urdf" / "mav_generic_odometry_sensor.gazebo"
SEED_ARGS = ["mav_name:=reed_quad_x", "namespace:=reed_quad_x", "enable_mavlink_interface:=true",
             "enable_ground_truth:=true", "enable_logging:=false", "log_file:=reed_quad_x",
             "wait_to_record_bag:=false"]
CASES = {
    "firefly_hex": (FIXTURES / "migrate" / "firefly_hex.xacro", []),
    "hummingbird_plus": (FIXTURES / "upstream_shapes" / "rotors_plus_quad" / "plusquad.xacro", []),
    "pelican_quad": (FIXTURES / "migrate" / "pelican_quad.xacro", []),
    "neo_tilted_hex": (FIXTURES / "rotors_neo" / "neo_balanced_tilt.sdf", []),
    "iris_px4_classic": (FIXTURES / "migrate" / "iris_classic.sdf", []),
    "seed_quad": (SEED, SEED_ARGS),
}
REL_TOL = 1e-9


def run(*args) -> int:
    reset_inputs()
    result = CliRunner().invoke(cli, [str(a) for a in args], standalone_mode=False)
    if result.exception is not None:
        raise result.exception
    return result.return_value


def port(model: Path, args: list[str], out: Path) -> Path:
    code = run("migrate", model, *args, "--to", "gz", "-o", out, "--force", "--format", "json")
    if code != 0:
        raise SystemExit(f"migrate {model}: exit {code}")
    return next(out.glob("*/model.sdf"))


def for_drake(model_sdf: Path, out: Path) -> Path:
    """The port without what Drake rejects: plugins, sensors, mesh geometry."""
    tree = etree.parse(str(model_sdf))
    for tag in ("plugin", "sensor"):
        for node in list(tree.iter(tag)):
            node.getparent().remove(node)
    for mesh in list(tree.iter("mesh")):
        shape = mesh.getparent().getparent()        # <visual>/<collision>
        shape.getparent().remove(shape)
    out.write_bytes(etree.tostring(tree))
    return out


def drake_reading(path: Path):
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    plant = MultibodyPlant(time_step=0.0)
    Parser(plant).AddModels(str(path))
    plant.Finalize()
    context = plant.CreateDefaultContext()
    mass = plant.CalcTotalMass(context)
    com = plant.CalcCenterOfMassPositionInWorld(context)
    poses = {}
    for index in range(plant.num_bodies()):
        body = plant.get_body(pydrake_body_index(index))
        if body.name() != "world":
            poses[body.name()] = body.EvalPoseInWorld(context).GetAsMatrix4()
    return mass, com, poses


def pydrake_body_index(index: int):
    from pydrake.multibody.tree import BodyIndex

    return BodyIndex(index)


def close(a, b, scale: float) -> bool:
    return bool(np.all(np.abs(np.asarray(a) - np.asarray(b)) <= REL_TOL * scale))


def median_time(repeats: int, fn) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    try:
        import pydrake  # noqa: F401
    except ImportError:
        raise SystemExit("needs Drake: pip install drake")
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name, (model, margs) in CASES.items():
            robot = load_robot(model, dict(a.split(":=", 1) for a in margs), [])
            props = whole_robot_pinocchio(robot)
            sdf = port(model, margs, tmp / name)
            mass, com, poses = drake_reading(for_drake(sdf, tmp / f"{name}.sdf"))
            # Drake poses the model's canonical (first) link at the world origin.
            base = poses[robot.base_link]
            T_base = np.linalg.inv(base)
            original_poses = link_poses(robot)
            size = max(1.0, max(np.linalg.norm(T[:3, 3]) for T in original_poses.values()))
            pose_ok = all(close(T_base @ poses[link], original_poses[link], size)
                          for link in poses if link in original_poses)
            com_base = (T_base @ np.append(com, 1.0))[:3]
            ok = (close(mass, props.mass_kg, props.mass_kg) and close(com_base, props.com_m, size)
                  and pose_ok)
            failed += not ok
            print(f"{name:18s} Drake mass {mass:.12g} kg, reedtool (original) "
                  f"{props.mass_kg:.12g} kg; COM {np.round(com_base, 9)} m; "
                  f"{len(poses)} link poses: {'EQUAL' if ok else 'DIFFERENT'}")

        out = tmp / "speed"
        seed_port = port(SEED, SEED_ARGS, out)
        yardstick = median_time(args.repeats, lambda: run("validate", SEED, *SEED_ARGS))
        t_migrate = median_time(args.repeats, lambda: port(SEED, SEED_ARGS, out))
        # --ignore-validation: the seed body inertia breaks the triangle inequality (I203, on
        # both sides); the flight is what is timed.
        t_hover = median_time(args.repeats, lambda: run("hover-test", seed_port,
                                                         "--ignore-validation"))
        print(f"seed quad: validate {yardstick:.2f} s (yardstick); migrate {t_migrate:.2f} s "
              f"({t_migrate / yardstick:.1f}x validate: write, read back, two hover flights); "
              f"hover-test of the port {t_hover:.2f} s ({t_hover / yardstick:.1f}x)")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
