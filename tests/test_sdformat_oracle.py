"""The libsdformat oracle can say no: it refuses what libsdformat refuses, by SDF version."""

import sdformat_oracle  # drake is in the test extra: CI never skips this oracle


def _model(version: str, link_name: str) -> str:
    return (f'<sdf version="{version}"><model name="m"><link name="{link_name}">'
            "<inertial><mass>1</mass></inertial></link></model></sdf>")


def test_a_plain_model_loads():
    assert sdformat_oracle.libsdformat_error_text(_model("1.9", "base_link")) is None


def test_double_colon_in_a_name_is_refused_from_sdf_1_8():
    # sdformat's recursiveSiblingNoDoubleColonInNames: '::' is the scope delimiter from 1.8 on.
    error = sdformat_oracle.libsdformat_error_text(_model("1.9", "gps0::link"))
    assert error is not None and "::" in error


def test_a_world_including_a_model_folder_loads(tmp_path):
    model = tmp_path / "models" / "box"
    model.mkdir(parents=True)
    (model / "model.config").write_text(
        '<?xml version="1.0"?><model><name>box</name><sdf version="1.9">model.sdf</sdf></model>')
    (model / "model.sdf").write_text(_model("1.9", "base_link").replace('name="m"', 'name="box"'))
    world = tmp_path / "world.sdf"
    world.write_text('<sdf version="1.9"><world name="w"><include><uri>model://box</uri>'
                     "</include></world></sdf>")
    assert sdformat_oracle.libsdformat_error(world, [tmp_path / "models"]) is None
    assert sdformat_oracle.body_count(world.with_name("world.sdf"), [tmp_path / "models"]) == 2
    # Without the model path the include cannot resolve, and libsdformat says so.
    assert "model://box" in sdformat_oracle.libsdformat_error(world)
