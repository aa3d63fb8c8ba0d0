"""load_robot and the Model / geometry views, against the URDF read independently (xml.etree)."""

import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import extwrench
from conftest import PAPER_URDF, SOURCE_DIR


def urdf_joints():
    root = ET.parse(PAPER_URDF).getroot()
    return [j for j in root.findall("joint") if j.get("type") != "fixed"], root


def test_model_matches_the_urdf(robot):
    joints, root = urdf_joints()
    assert robot.nq == len(joints) == 7
    assert robot.joint_names == [j.get("name") for j in joints]
    assert robot.bodies == ["link0"] + [j.find("child").get("link") for j in joints]
    limit = lambda key: np.array([float(j.find("limit").get(key)) for j in joints])
    assert np.array_equal(robot.lower, limit("lower"))
    assert np.array_equal(robot.upper, limit("upper"))
    assert np.array_equal(robot.velocity_limit, limit("velocity"))
    assert np.array_equal(robot.effort_limit, limit("effort"))
    masses = {l.get("name"): float(l.find("inertial/mass").get("value"))
              for l in root.findall("link") if l.find("inertial") is not None}
    assert robot.masses[1:].tolist() == [masses[b] for b in robot.bodies[1:]]
    assert np.array_equal(robot.gravity, [0, 0, -9.81])
    assert robot.parents == list(range(-1, 7))
    assert "sensor" in robot.frames
    assert robot.joints[0]["type"] == "revolute" and robot.joints[0]["placement"].shape == (4, 4)
    assert len(robot.shapes) == len(root.findall("link/collision"))
    # The sensor frame is 0.31 m below O_0 (the file's comment): X_WS is a translation.
    np.testing.assert_array_equal(robot.default_sensor_pose[:3, :3], np.eye(3))
    assert robot.default_sensor_pose[2, 3] == pytest.approx(-0.31)


def test_gravity_override_and_dh(tmp_path):
    r = extwrench.load_robot(PAPER_URDF, gravity=[0, 0, -1.62])
    assert np.array_equal(r.gravity, [0, 0, -1.62])
    dh = extwrench.load_robot(SOURCE_DIR / "models" / "paper_arm.yaml")
    assert dh.nq == 7


def test_package_path(tmp_path):
    pkg = tmp_path / "pkgs" / "mybot"
    pkg.mkdir(parents=True)
    (pkg / "tri.stl").write_text(
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid t\n")
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(
        "<robot name='r'>\n<link name='base'/>\n<joint name='j' type='revolute'>\n"
        "<parent link='base'/><child link='arm'/><axis xyz='0 0 1'/>\n"
        "<limit lower='-1' upper='1' velocity='1' effort='1'/></joint>\n<link name='arm'>\n"
        "<inertial><mass value='1'/><inertia ixx='1' ixy='0' ixz='0' iyy='1' iyz='0' izz='1'/>"
        "</inertial>\n<collision><geometry><mesh filename='package://mybot/tri.stl'/></geometry>"
        "</collision>\n</link>\n</robot>\n")
    r = extwrench.load_robot(urdf, package_path=[tmp_path / "pkgs"], use_ros_package_path=False)
    (shape,) = r.shapes
    assert shape["type"] == "mesh" and shape["triangles"].shape == (1, 3)
    assert shape["vertices"].shape == (3, 3)
    # Rows are vertices and triangles (C order, as docs/python.md says of every result).
    assert shape["vertices"].flags.c_contiguous and shape["triangles"].dtype == np.int64
    assert sorted(map(tuple, shape["vertices"][shape["triangles"][0]].tolist())) == [
        (0, 0, 0), (0, 1, 0), (1, 0, 0)]
    with pytest.raises(extwrench.Error, match="mybot"):
        extwrench.load_robot(urdf, use_ros_package_path=False)


def test_errors_carry_the_cpp_message(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'>\n<link name='a'>\n<inertial><mass value='abc'/><inertia ixx='1' ixy='0' ixz='0' iyy='1' iyz='0' izz='1'/></inertial>"
                   "</link>\n</robot>\n")
    with pytest.raises(extwrench.Error) as info:
        extwrench.load_robot(bad)
    text = str(info.value)
    assert "bad.urdf:" in text and "abc" in text
    with pytest.raises(TypeError):
        extwrench.load_robot(PAPER_URDF, gravity="down")
    with pytest.raises(ValueError, match="gravity"):
        extwrench.load_robot(PAPER_URDF, gravity=[0, 0])


def test_version_and_import():
    out = subprocess.run([sys.executable, "-c", "import extwrench; print(extwrench.__version__)"],
                         capture_output=True, text=True, check=True).stdout.strip()
    cmake = (SOURCE_DIR / "CMakeLists.txt").read_text()
    assert "project(extwrench VERSION %s " % out in cmake


def test_stubs_cover_the_module():
    import ast
    import pathlib
    from extwrench import _extwrench
    package = pathlib.Path(extwrench.__file__).parent
    tree = ast.parse((package / "_extwrench.pyi").read_text())
    stubbed = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    stubbed |= {t.id for n in tree.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    public = {n for n in dir(_extwrench) if not n.startswith("__")}
    assert public - stubbed == set()
    for cls in ("Robot", "Estimate", "ContactEstimator", "ExternalWrench"):
        node = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls)
        members = {m.name for m in node.body if isinstance(m, ast.FunctionDef)}
        members |= {m.target.id for m in node.body if isinstance(m, ast.AnnAssign)}
        actual = {m for m in dir(getattr(_extwrench, cls)) if not m.startswith("_")}
        assert actual - members == set(), cls
    assert (package / "py.typed").exists() and (package / "__init__.pyi").exists()


def test_locked_joints_equal_the_urdf_with_those_joints_fixed(tmp_path):
    # The reference is the same file with the last joint made fixed by a text edit (locked at 0,
    # its origin is the fixed joint's): the two must give the same reduced robot and torques.
    text = PAPER_URDF.read_text()
    joints, _ = urdf_joints()
    name = joints[-1].get("name")
    start = text.index(f'<joint name="{name}"')
    head = text[start:text.index(">", start) + 1]
    fixed = tmp_path / "fixed.urdf"
    fixed.write_text(text.replace(head, head.replace('type="revolute"', 'type="fixed"')))
    locked = extwrench.load_robot(PAPER_URDF, locked_joints={name: 0.0})
    reference = extwrench.load_robot(fixed)
    assert locked.nq == reference.nq == 6
    assert name not in locked.joint_names
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, dq, ddq = (rng.uniform(-1, 1, 6) for _ in range(3))
        np.testing.assert_allclose(extwrench.rnea(locked, q, dq, ddq),
                                   extwrench.rnea(reference, q, dq, ddq), rtol=0, atol=1e-12)
    with pytest.raises(extwrench.Error, match="nope"):
        extwrench.load_robot(PAPER_URDF, locked_joints={"nope": 0.0})


def test_mjcf_loads_as_in_the_cli():
    """The paper arm's MJCF twin through MuJoCo's compiler, when the module was built with it
    (as the CLI is): the same joints and masses as its URDF, read by our parser."""
    mjcf = SOURCE_DIR / "models" / "paper_arm.xml"
    try:
        twin = extwrench.load_robot(mjcf)
    except extwrench.Error as e:
        if "MJCF needs extwrench built with MuJoCo" in str(e):
            pytest.skip("module built without MuJoCo")
        raise
    urdf = extwrench.load_robot(PAPER_URDF)
    assert twin.nq == urdf.nq == 7
    assert np.isclose(twin.masses.sum(), urdf.masses.sum(), rtol=1e-9, atol=1e-12)
    assert np.allclose(twin.lower, urdf.lower) and np.allclose(twin.upper, urdf.upper)
    assert extwrench.load_robot(mjcf, tip_body="link3").nq == 3  # a chain of it, as --tip-body
