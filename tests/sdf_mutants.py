"""A corpus of mutated SDF models, for holding validate to libsdformat (test_sdformat_parity).

Three bases of our own, in the shapes of real models (the facts carry over, not the text):

* `quad_merge` (SDF 1.9): an x500-like quad as PX4-gazebo-models writes it, a model
  `quad_base` (base_link with IMU, four rotor links on revolute joints) merged into `quad`
  by `<include merge="true">`, with motor plugins and a frame attached to base_link.
* `nested_rig` (SDF 1.9): a base link, a nested model `arm` (two links, an elbow joint)
  mounted by a joint whose child is `arm::upper`, frames with `attached_to`, and poses
  `relative_to` a frame, a joint and a nested model's link.
* `classic_gps` (SDF 1.6, also written as 1.7): a Classic iris-like body that includes a
  GPS model without merging and fixes its link by the scoped name `gps0::link`.

`mutants()` applies each mutation that fits each base and version (`::` in link, joint,
frame, model and visual names; duplicate and colliding sibling names; reserved names; a
joint's child equal to its parent, `world` or nothing; frames attached to nothing, to
themselves or in a cycle; poses relative to nothing or in a cycle; a canonical_link
naming nothing; a model without links; no `<sdf version>`; two top-level models; a top
model posed relative_to; world frames, poses and duplicate models; a static model's
names), plus mutations libsdformat must accept (a plugin's name with `::`, a scoped
canonical_link, a static model without links, a visual and a collision of one name, a
world frame attached inside a model).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from lxml import etree

_INERTIAL = ("<inertial><mass>{m}</mass><inertia><ixx>{i}</ixx><ixy>0</ixy><ixz>0</ixz>"
             "<iyy>{i}</iyy><iyz>0</iyz><izz>{i}</izz></inertia></inertial>")


def _inertial(mass_kg: float) -> str:
    # A solid 0.1 m cube's inertia is m*(0.1^2+0.1^2)/12; its exact value is irrelevant here.
    return _INERTIAL.format(m=mass_kg, i=f"{mass_kg * 0.02 / 12:.6g}")


def _rotor(i: int, x: float, y: float) -> str:
    return (f'<link name="rotor_{i}"><pose>{x} {y} 0.06 0 0 0</pose>{_inertial(0.016)}'
            f'<visual name="rotor_{i}_visual"><geometry><cylinder><radius>0.12</radius>'
            f"<length>0.005</length></cylinder></geometry></visual></link>"
            f'<joint name="rotor_{i}_joint" type="revolute"><child>rotor_{i}</child>'
            f"<parent>base_link</parent><axis><xyz>0 0 1</xyz><limit><lower>-1e16</lower>"
            f"<upper>1e16</upper></limit></axis></joint>")


_QUAD_BASE = (
    '<sdf version="{v}"><model name="quad_base"><pose>0 0 0.24 0 0 0</pose>'
    f'<link name="base_link">{_inertial(2.0)}'
    '<visual name="base_link_visual"><geometry><box><size>0.35 0.35 0.1</size></box>'
    '</geometry></visual><collision name="base_link_collision"><geometry><box>'
    "<size>0.35 0.35 0.1</size></box></geometry></collision>"
    '<sensor name="imu_sensor" type="imu"><always_on>1</always_on><update_rate>250'
    "</update_rate></sensor></link>"
    + "".join(_rotor(i, x, y) for i, (x, y) in
              enumerate([(0.17, -0.17), (-0.17, 0.17), (0.17, 0.17), (-0.17, -0.17)]))
    + "</model></sdf>")

_MOTOR = ('<plugin filename="gz-sim-multicopter-motor-model-system" '
          'name="gz::sim::systems::MulticopterMotorModel"><jointName>rotor_{i}_joint'
          "</jointName><linkName>rotor_{i}</linkName><turningDirection>{d}</turningDirection>"
          "<maxRotVelocity>1000</maxRotVelocity><motorConstant>8.54858e-06</motorConstant>"
          "<momentConstant>0.016</momentConstant><motorNumber>{i}</motorNumber>"
          "<commandSubTopic>command/motor_speed</commandSubTopic></plugin>")

_QUAD = (
    '<sdf version="{v}"><model name="quad"><include merge="true">'
    "<uri>model://quad_base</uri></include>"
    '<frame name="imu_frame" attached_to="base_link"><pose>0 0 0.02 0 0 0</pose></frame>'
    + "".join(_MOTOR.format(i=i, d=d) for i, d in enumerate(["ccw", "ccw", "cw", "cw"]))
    + "</model></sdf>")

_NESTED = (
    '<sdf version="{v}"><model name="rig">'
    f'<link name="base">{_inertial(1.0)}</link>'
    '<frame name="mount_frame" attached_to="base"><pose>0.2 0 0.1 0 0 0</pose></frame>'
    '<model name="arm"><pose relative_to="mount_frame">0 0 0 0 0 0</pose>'
    f'<link name="upper">{_inertial(0.3)}</link>'
    f'<link name="lower"><pose relative_to="elbow_frame">0 0 0 0 0 0</pose>{_inertial(0.2)}'
    "</link>"
    '<frame name="elbow_frame" attached_to="upper"><pose>0.3 0 0 0 0 0</pose></frame>'
    '<joint name="elbow" type="revolute"><parent>upper</parent><child>lower</child>'
    "<axis><xyz>0 1 0</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis></joint>"
    "</model>"
    '<joint name="mount" type="fixed"><parent>base</parent><child>arm::upper</child></joint>'
    '<frame name="tool" attached_to="mount"><pose>0 0 0.05 0 0 0</pose></frame>'
    f'<link name="camera"><pose relative_to="tool">0 0 0 0 0 0</pose>{_inertial(0.05)}'
    '<visual name="camera_visual"><geometry><box><size>0.03 0.03 0.03</size></box>'
    "</geometry></visual></link>"
    '<joint name="camera_joint" type="fixed"><parent>base</parent><child>camera</child>'
    "</joint></model></sdf>")

_GPS = ('<sdf version="{v}"><model name="gps"><link name="link">'
        f'{_inertial(0.015)}<sensor name="gps" type="gps"><update_rate>5</update_rate>'
        "</sensor></link></model></sdf>")

_CLASSIC = (
    '<sdf version="{v}"><model name="iris">'
    f'<link name="base_link"><pose>0 0 0.194 0 0 0</pose>{_inertial(1.5)}'
    '<collision name="base_link_collision"><geometry><box><size>0.47 0.47 0.11</size></box>'
    "</geometry></collision></link>"
    + "".join(_rotor(i, x, y) for i, (x, y) in
              enumerate([(0.13, -0.22), (-0.13, 0.2), (0.13, 0.22), (-0.13, -0.2)]))
    + '<include><uri>model://gps</uri><pose>0.1 0 0.1 0 0 0</pose><name>gps0</name></include>'
    '<joint name="gps0_joint" type="fixed"><child>gps0::link</child><parent>base_link</parent>'
    "</joint></model></sdf>")


_WORLD = (
    '<sdf version="{v}"><world name="field">'
    '<model name="ground_plane"><static>true</static><link name="link"><collision '
    'name="collision"><geometry><plane><normal>0 0 1</normal></plane></geometry></collision>'
    "</link></model>"
    '<frame name="landing_pad" attached_to="ground_plane"><pose>2 0 0 0 0 0</pose></frame>'
    '<include><uri>model://quad</uri><name>quad_0</name>'
    '<pose relative_to="landing_pad">0 0 0.2 0 0 0</pose></include>'
    '<model name="cart"><pose relative_to="landing_pad">1 0 0.1 0 0 0</pose>'
    f'<link name="chassis">{_inertial(10.0)}<visual name="chassis_visual"><geometry><box>'
    "<size>0.6 0.4 0.2</size></box></geometry></visual></link>"
    f'<link name="wheel"><pose>0.3 0.25 0 1.5708 0 0</pose>{_inertial(0.5)}</link>'
    '<joint name="wheel_joint" type="revolute"><parent>chassis</parent><child>wheel</child>'
    "<axis><xyz>0 0 1</xyz><limit><lower>-1e16</lower><upper>1e16</upper></limit></axis>"
    "</joint></model></world></sdf>")


@dataclass(frozen=True)
class Base:
    name: str
    version: str
    top: str                       # the model file's text
    models: dict[str, str]         # model folder name -> its model.sdf text
    # The mutations worth running on this base (None: all); a version variant of a base
    # needs only those whose verdict depends on the version, to keep the corpus quick.
    only: tuple[str, ...] | None = None
    top_path: str | None = None    # where the top file goes (default models/NAME/model.sdf)

    def write(self, root: Path, top_text: str | None = None,
              models: dict[str, str] | None = None) -> Path:
        """The model folders and the top file under `root`; the top file's path."""
        for name, text in {**self.models, **(models or {})}.items():
            folder = root / "models" / name
            folder.mkdir(parents=True, exist_ok=True)
            (folder / "model.config").write_text(
                f'<?xml version="1.0"?><model><name>{name}</name>'
                f'<sdf version="{self.version}">model.sdf</sdf></model>')
            (folder / "model.sdf").write_text(text)
        top = root / (self.top_path or f"models/{self.name}/model.sdf")
        top.parent.mkdir(parents=True, exist_ok=True)
        top.write_text(top_text if top_text is not None else self.top)
        return top


def bases() -> list[Base]:
    return [
        Base("quad", "1.9", _QUAD.format(v="1.9"), {"quad_base": _QUAD_BASE.format(v="1.9")}),
        Base("rig", "1.9", _NESTED.format(v="1.9"), {}),
        Base("rig", "1.8", _NESTED.format(v="1.8"), {}, _BY_VERSION),
        Base("iris", "1.6", _CLASSIC.format(v="1.6"), {"gps": _GPS.format(v="1.6")}),
        Base("iris", "1.7", _CLASSIC.format(v="1.7"), {"gps": _GPS.format(v="1.7")},
             _BY_VERSION),
        # A world: a static ground plane, a world frame, the quad included relative to it
        # (validate reads the quad, which has motors) and a cart beside it.
        Base("field", "1.9", _WORLD.format(v="1.9"),
             {"quad": _QUAD.format(v="1.9"), "quad_base": _QUAD_BASE.format(v="1.9")},
             _WORLD_MUTATIONS, "worlds/field.sdf"),
        # A 1.9 file including a Classic 1.6 model: each file is read at its own version.
        Base("iris", "1.9", _CLASSIC.format(v="1.9"), {"gps": _GPS.format(v="1.6")},
             _BY_VERSION),
    ]


# Mutations whose verdict depends on the declared version ('::' from 1.8, collisions
# across types from 1.7), plus the included-file mutations.
_BY_VERSION = ("dc_link", "dc_joint", "dc_frame", "dc_model", "dc_visual", "dup_link",
               "link_named_as_joint", "frame_named_as_link", "pose_relative_own_joint")


# ------------------------------------------------------------------ mutations
# Each takes the parsed top file (and its version) and edits it in place; it returns False
# when it does not apply to that base.

def _model(root):
    """The model a mutation edits: the file's model, or in a world its last model."""
    model = root.find("model")
    return model if model is not None else root.find("world").findall("model")[-1]


def _world(root):
    return root.find("world")


def _find(root, tag, name):
    return next((el for el in root.iter(tag) if el.get("name") == name), None)


def _rename_link(root, old, new) -> bool:
    link = _find(root, "link", old)
    if link is None:
        return False
    link.set("name", new)
    for el in root.iter("parent", "child"):
        if (el.text or "").strip() == old:
            el.text = new
    for el in root.iter():
        for attr in ("attached_to", "relative_to", "canonical_link"):
            if el.get(attr) == old:
                el.set(attr, new)
    return True


def _first_link(root):
    return next(iter(_model(root).iterfind("link")), None)


def _first_joint(root):
    return next(iter(_model(root).iterfind("joint")), None)


def dc_link(root, v):
    """A link of the top model named with '::' (the flattened-include shape)."""
    link = _first_link(root)
    return link is not None and _rename_link(root, link.get("name"), "gps0::" +
                                             link.get("name"))


def dc_joint(root, v):
    joint = _first_joint(root)
    if joint is None:
        return False
    joint.set("name", "sub::" + joint.get("name"))
    return True


def dc_frame(root, v):
    frame = _model(root).find("frame")
    if frame is None:
        return False
    old = frame.get("name")
    frame.set("name", "a::" + old)
    for el in root.iter():
        for attr in ("attached_to", "relative_to"):
            if el.get(attr) == old:
                el.set(attr, "a::" + old)
    return True


def dc_model(root, v):
    """The top model's own name with '::'."""
    _model(root).set("name", "fleet::" + _model(root).get("name"))
    return True


def dc_visual(root, v):
    visual = next(root.iter("visual", "collision"), None)
    if visual is None:
        return False
    visual.set("name", "body::" + visual.get("name"))
    return True


def dc_plugin_name(root, v):
    """Accepted: a plugin's name is not an SDF name (gz::sim::systems::...)."""
    plugin = etree.SubElement(_model(root), "plugin", filename="libfoo.so",
                              name="foo::bar::Baz")
    etree.SubElement(plugin, "link_name").text = "a::b"
    return True


def dup_link(root, v):
    link = _first_link(root)
    if link is None:
        return False
    _model(root).append(copy.deepcopy(link))
    return True


def dup_joint(root, v):
    joint = _first_joint(root)
    if joint is None:
        return False
    _model(root).append(copy.deepcopy(joint))
    return True


def link_named_as_joint(root, v):
    """A link that takes a joint's name: an error from 1.7, renamed below."""
    joint = _first_joint(root)
    if joint is None:
        return False
    link = etree.SubElement(_model(root), "link", name=joint.get("name"))
    link.append(etree.fromstring(_inertial(0.01)))
    extra = etree.SubElement(_model(root), "joint", name="extra_fix", type="fixed")
    etree.SubElement(extra, "parent").text = _first_link(root).get("name")
    etree.SubElement(extra, "child").text = joint.get("name")
    return True


def frame_named_as_link(root, v):
    link = _first_link(root)
    if link is None:
        return False
    etree.SubElement(_model(root), "frame", name=link.get("name"))
    return True


def dup_nested_model(root, v):
    nested = _model(root).find("model")
    if nested is None:
        return False
    _model(root).append(copy.deepcopy(nested))
    return True


def dup_visual(root, v):
    link = next((l for l in root.iter("link") if l.find("visual") is not None), None)
    if link is None:
        return False
    link.append(copy.deepcopy(link.find("visual")))
    return True


def _reserved(tag, name):
    def mutate(root, v):
        if tag == "link":
            link = _first_link(root)
            return link is not None and _rename_link(root, link.get("name"), name)
        if tag == "joint":
            joint = _first_joint(root)
            if joint is None:
                return False
            joint.set("name", name)
            return True
        if tag == "frame":
            etree.SubElement(_model(root), "frame", name=name)
            return True
        if tag == "model":
            _model(root).set("name", name)
            return True
        return False
    mutate.__name__ = f"reserved_{tag}_{name.strip('_') or name}"
    mutate.__doc__ = f"A {tag} named '{name}'."
    return mutate


def joint_child_is_parent(root, v):
    joint = _first_joint(root)
    if joint is None:
        return False
    joint.find("child").text = joint.find("parent").text
    return True


def joint_child_world(root, v):
    joint = _first_joint(root)
    if joint is None:
        return False
    joint.find("child").text = "world"
    return True


def joint_parent_itself(root, v):
    joint = _first_joint(root)
    if joint is None:
        return False
    joint.find("parent").text = joint.get("name")
    return True


def joint_child_missing(root, v):
    joint = _first_joint(root)
    if joint is None:
        return False
    joint.find("child").text = "no_such_link"
    return True


def joint_parent_missing(root, v):
    joint = _first_joint(root)
    if joint is None:
        return False
    joint.find("parent").text = "no_such_link"
    return True


def joint_parent_frame_on_child(root, v):
    """The parent is a frame attached to the child link: both resolve to one link."""
    joint = _first_joint(root)
    if joint is None:
        return False
    child = joint.find("child").text.strip()
    etree.SubElement(_model(root), "frame", name="on_child", attached_to=child)
    joint.find("parent").text = "on_child"
    return True


def frame_attached_missing(root, v):
    etree.SubElement(_model(root), "frame", name="lost", attached_to="no_such_frame")
    return True


def frame_attached_itself(root, v):
    etree.SubElement(_model(root), "frame", name="selfish", attached_to="selfish")
    return True


def frame_attached_cycle(root, v):
    etree.SubElement(_model(root), "frame", name="ping", attached_to="pong")
    etree.SubElement(_model(root), "frame", name="pong", attached_to="ping")
    return True


def _pose(el, relative_to):
    pose = el.find("pose")
    if pose is None:
        pose = etree.SubElement(el, "pose")
        pose.text = "0 0 0 0 0 0"
    pose.set("relative_to", relative_to)


def pose_relative_missing(root, v):
    link = _first_link(root)
    if link is None:
        return False
    _pose(link, "no_such_frame")
    return True


def pose_relative_itself(root, v):
    link = _first_link(root)
    if link is None:
        return False
    _pose(link, link.get("name"))
    return True


def pose_relative_own_joint(root, v):
    """A child link posed relative to its own joint, which is posed relative to it."""
    joint = _first_joint(root)
    if joint is None:
        return False
    child = _find(root, "link", joint.find("child").text.strip())
    if child is None:
        return False
    _pose(child, joint.get("name"))
    return True


def pose_frame_cycle(root, v):
    a = etree.SubElement(_model(root), "frame", name="fa")
    b = etree.SubElement(_model(root), "frame", name="fb")
    _pose(a, "fb")
    _pose(b, "fa")
    return True


def canonical_missing(root, v):
    _model(root).set("canonical_link", "no_such_link")
    return True


def canonical_nested(root, v):
    """Accepted from 1.8: the canonical link of a nested model, scoped."""
    nested = _model(root).find("model")
    if nested is None:
        return False
    _model(root).set("canonical_link", f"{nested.get('name')}::{nested.find('link').get('name')}")
    return True


def nested_without_link(root, v):
    etree.SubElement(_model(root), "model", name="empty_pod")
    return True


def nested_without_link_static(root, v):
    """Accepted: a static model needs no link."""
    pod = etree.SubElement(_model(root), "model", name="static_pod")
    etree.SubElement(pod, "static").text = "true"
    return True


def visual_collision_same_name(root, v):
    """Accepted: a visual and a collision of one link may share a name."""
    link = next((l for l in root.iter("link") if l.find("visual") is not None), None)
    if link is None:
        return False
    collision = etree.SubElement(link, "collision", name=link.find("visual").get("name"))
    collision.append(copy.deepcopy(link.find("visual").find("geometry")))
    return True


def no_version(root, v):
    del root.attrib["version"]
    return True


def world_dup_model(root, v):
    world = _world(root)
    if world is None:
        return False
    world.append(copy.deepcopy(_model(root)))
    return True


def world_frame_missing(root, v):
    world = _world(root)
    if world is None:
        return False
    etree.SubElement(world, "frame", name="lost", attached_to="no_such_model")
    return True


def world_frame_cycle(root, v):
    world = _world(root)
    if world is None:
        return False
    etree.SubElement(world, "frame", name="ping", attached_to="pong")
    etree.SubElement(world, "frame", name="pong", attached_to="ping")
    return True


def world_pose_missing(root, v):
    world = _world(root)
    if world is None:
        return False
    _pose(_model(root), "no_such_frame")
    return True


def world_frame_in_model(root, v):
    """Accepted: a world frame attached to a frame inside a model, scoped."""
    world = _world(root)
    if world is None:
        return False
    etree.SubElement(world, "frame", name="wheel_hub", attached_to="cart::wheel_joint")
    return True


def static_link_double_colon(root, v):
    """A link of the static ground plane, which validate does not read, named with '::'."""
    world = _world(root)
    if world is None:
        return False
    world.find("model").find("link").set("name", "ground::link")
    return True


def static_joint_child_missing(root, v):
    world = _world(root)
    if world is None:
        return False
    joint = etree.SubElement(world.find("model"), "joint", name="anchor", type="fixed")
    etree.SubElement(joint, "parent").text = "link"
    etree.SubElement(joint, "child").text = "no_such_link"
    return True


def static_duplicate_link(root, v):
    world = _world(root)
    if world is None:
        return False
    ground = world.find("model")
    ground.append(copy.deepcopy(ground.find("link")))
    return True


def root_two_models(root, v):
    """A second model at the top of a model file (outside a world)."""
    if root.find("model") is None:
        return False
    root.append(copy.deepcopy(root.find("model")))
    root[-1].set("name", "copy")
    return True


def top_pose_relative(root, v):
    """The file's top model posed relative to one of its links."""
    model = root.find("model")
    link = _first_link(root) if model is not None else None
    if link is None:
        return False
    pose = model.find("pose")
    if pose is None:
        pose = etree.Element("pose")
        pose.text = "0 0 0 0 0 0"
        model.insert(0, pose)
    pose.set("relative_to", link.get("name"))
    return True


_WORLD_MUTATIONS = (
    "world_dup_model", "world_frame_missing", "world_frame_cycle", "world_pose_missing",
    "world_frame_in_model", "static_link_double_colon", "static_joint_child_missing",
    "static_duplicate_link", "dc_link", "dc_model", "dup_link", "link_named_as_joint",
    "reserved_model_world", "joint_child_is_parent", "joint_child_missing",
    "frame_attached_missing", "pose_relative_own_joint", "canonical_missing",
    "nested_without_link", "dup_visual")


MUTATIONS: list[Callable] = [
    dc_link, dc_joint, dc_frame, dc_model, dc_visual, dc_plugin_name,
    dup_link, dup_joint, link_named_as_joint, frame_named_as_link, dup_nested_model,
    dup_visual,
    _reserved("link", "world"), _reserved("link", "__model__"), _reserved("joint", "__j__"),
    _reserved("frame", "__f__"), _reserved("model", "world"),
    joint_child_is_parent, joint_child_world, joint_parent_itself, joint_child_missing,
    joint_parent_missing, joint_parent_frame_on_child,
    frame_attached_missing, frame_attached_itself, frame_attached_cycle,
    pose_relative_missing, pose_relative_itself, pose_relative_own_joint, pose_frame_cycle,
    canonical_missing, canonical_nested, nested_without_link, nested_without_link_static,
    visual_collision_same_name, no_version,
    world_dup_model, world_frame_missing, world_frame_cycle, world_pose_missing,
    world_frame_in_model, static_link_double_colon, static_joint_child_missing,
    static_duplicate_link, root_two_models, top_pose_relative,
]
# Applied to the included model file as well, where a base includes one.
INCLUDED_MUTATIONS: list[Callable] = [
    dc_link, dc_visual, dup_visual, _reserved("link", "world"), joint_child_is_parent,
    frame_attached_missing, pose_relative_missing, canonical_missing,
]


@dataclass(frozen=True)
class Mutant:
    base: Base
    mutation: str
    text: str
    models: tuple = ()             # (folder, model.sdf text) replacing the base's

    @property
    def id(self) -> str:
        included = "-".join(f"{name}@{self.base.models[name][14:17]}"
                            for name, _ in self.models)
        return "-".join(filter(None, [self.base.name, self.base.version, included,
                                      self.mutation]))

    def write(self, root: Path) -> Path:
        return self.base.write(root, self.text, dict(self.models))


def _mutated(text: str, mutate) -> str | None:
    root = etree.fromstring(text)
    if mutate(root, root.get("version")) is False:
        return None
    return etree.tostring(root, encoding="unicode")


def mutants() -> list[Mutant]:
    """Every mutation that applies, on every base (the unmutated bases first)."""
    found = []
    for base in bases():
        found.append(Mutant(base, "unmutated", base.top))
        for mutate in MUTATIONS:
            if base.only is not None and mutate.__name__ not in base.only:
                continue
            text = _mutated(base.top, mutate)
            if text is not None:
                found.append(Mutant(base, mutate.__name__, text))
        for name, model_text in base.models.items():
            if base.top_path:
                continue   # a world's included models are the quad base's, mutated there
            for mutate in INCLUDED_MUTATIONS:
                text = _mutated(model_text, mutate)
                if text is not None:
                    found.append(Mutant(base, mutate.__name__, base.top, ((name, text),)))
    return found
