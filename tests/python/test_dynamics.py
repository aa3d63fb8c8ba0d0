"""Dynamics from Python against the C++ library on the same inputs (bit for bit, through
tests/python/dynamics_reference.cpp), physical identities, layouts, dtypes, errors, leaks."""

import gc
import subprocess
import sys

import numpy as np
import pytest

import extwrench
from conftest import PAPER_URDF, bits, random_state


def reference(exe, q, dq, ddq, tau, body, point, force, moment):
    numbers = list(q) + list(dq) + list(ddq) + list(tau) + [body] + list(point) + list(force) \
        + list(moment)
    text = " ".join(repr(float(x)) if i != 4 * len(q) else str(int(x))
                    for i, x in enumerate(numbers))
    out = subprocess.run([exe, str(PAPER_URDF)], input=text, capture_output=True, text=True,
                         check=True).stdout
    return {line.split()[0]: np.array([float(v) for v in line.split()[1:]])
            for line in out.splitlines()}


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_bit_identical_to_cpp(robot, dynamics_reference, seed):
    rng = np.random.default_rng(seed)
    n = robot.nq
    q, dq, ddq = random_state(rng, n)
    tau = rng.uniform(-20, 20, n)
    body = int(rng.integers(1, n + 1))
    point, force, moment = rng.uniform(-0.5, 0.5, 3), rng.uniform(-30, 30, 3), rng.uniform(-3, 3, 3)
    ref = reference(dynamics_reference, q, dq, ddq, tau, body, point, force, moment)
    w = extwrench.ExternalWrench(body, force, point, moment)
    got = {
        "rnea": extwrench.rnea(robot, q, dq, ddq),
        "sensor_reading": extwrench.sensor_reading(robot, q, dq, ddq),
        "rnea_wrench": extwrench.rnea(robot, q, dq, ddq, [w]),
        "sensor_reading_wrench": extwrench.sensor_reading(robot, q, dq, ddq, w),
        "crba": extwrench.crba(robot, q),
        "bias": extwrench.bias(robot, q, dq),
        "gravity": extwrench.gravity(robot, q),
        "coriolis_matrix": extwrench.coriolis_matrix(robot, q, dq),
        "jacobian_body": extwrench.jacobian(robot, q, body),
        "jacobian_point": extwrench.jacobian(robot, q, robot.bodies[body], point),
        "forward_dynamics": extwrench.forward_dynamics(robot, q, dq, tau),
    }
    poses = extwrench.forward_kinematics(robot, q)
    for b in range(n + 1):
        got["pose_%d" % b] = poses[b]
    assert set(got) == set(ref)
    for key, value in got.items():
        assert np.array_equal(bits(value.ravel()), bits(ref[key])), key


def test_shapes_and_dtypes(robot):
    n = robot.nq
    q = np.zeros(n)
    shapes = {
        extwrench.rnea(robot, q, q, q).shape: (n,),
        extwrench.crba(robot, q).shape: (n, n),
        extwrench.coriolis_matrix(robot, q, q).shape: (n, n),
        extwrench.jacobian(robot, q, n).shape: (6, n),
        extwrench.forward_kinematics(robot, q).shape: (n + 1, 4, 4),
        extwrench.sensor_reading(robot, q, q, q).shape: (6,),
    }
    for got, want in shapes.items():
        assert got == want
    m = extwrench.crba(robot, q)
    assert m.dtype == np.float64 and m.flags.c_contiguous and m.flags.writeable


def test_physical_identities(robot):
    rng = np.random.default_rng(7)
    q, dq, _ = random_state(rng, robot.nq)
    tau = rng.uniform(-10, 10, robot.nq)
    ddq = extwrench.forward_dynamics(robot, q, dq, tau)
    # Forward dynamics inverts inverse dynamics; B ddq + c = tau; g = c at dq = 0.
    np.testing.assert_allclose(extwrench.rnea(robot, q, dq, ddq), tau, atol=1e-9)
    np.testing.assert_allclose(extwrench.crba(robot, q) @ ddq + extwrench.bias(robot, q, dq), tau,
                               atol=1e-9)
    np.testing.assert_allclose(extwrench.gravity(robot, q),
                               extwrench.bias(robot, q, np.zeros(robot.nq)), atol=1e-12)
    # A wrench on a body: tau changes by -J^T [F; M + p x F ...] (here: pure force at a point).
    body, point, force = 4, rng.uniform(-0.3, 0.3, 3), np.array([3.0, -2.0, 5.0])
    w = extwrench.ExternalWrench(body, force, point)
    J = extwrench.jacobian(robot, q, body, point)
    np.testing.assert_allclose(
        extwrench.rnea(robot, q, dq, ddq, [w]), tau - J[:3].T @ force, atol=1e-9)


def test_layouts_give_the_same_bits(robot):
    rng = np.random.default_rng(3)
    n = robot.nq
    block = rng.uniform(-1, 1, (4 * n, 3))
    f_order = np.asfortranarray(block)
    q = block[::4, 1]                          # non-contiguous slice
    assert not q.flags.c_contiguous
    base = extwrench.rnea(robot, q.copy(), block[:n, 0].copy(), block[:n, 2].copy())
    for q_, dq_, ddq_ in [(q, block[:n, 0], block[:n, 2]),
                          (f_order[::4, 1], f_order[:n, 0], f_order[:n, 2]),
                          (list(q), tuple(block[:n, 0]), list(block[:n, 2])),
                          (q[::-1][::-1], block[:n, 0], block[:n, 2])]:
        assert np.array_equal(extwrench.rnea(robot, q_, dq_, ddq_), base)
    # Integer input is converted exactly; float32 goes through float64 once.
    zeros = np.zeros(n, dtype=np.int32)
    assert np.array_equal(extwrench.gravity(robot, zeros), extwrench.gravity(robot, np.zeros(n)))


@pytest.mark.parametrize("bad, exc, words", [
    (np.zeros(3), ValueError, ["q", "shape (7,)", "(3,)"]),
    (np.zeros((7, 1)), ValueError, ["q", "1-D"]),
    (np.zeros(7, dtype=complex), TypeError, ["q", "complex128"]),
    (np.array(["a"] * 7), TypeError, ["q", "dtype"]),
    (np.zeros(7, dtype=bool), TypeError, ["q", "bool"]),
    ([0.0] * 6 + [float("nan")], ValueError, ["q[6]", "nan"]),
    (np.array([0, 0, np.inf, 0, 0, 0, 0.0]), ValueError, ["q[2]", "inf"]),
    (None, TypeError, ["q"]),
    ("abc", TypeError, ["q"]),
])
def test_bad_input_names_the_argument(robot, bad, exc, words):
    with pytest.raises(exc) as info:
        extwrench.rnea(robot, bad, np.zeros(7), np.zeros(7))
    for w in words:
        assert w in str(info.value)


def test_other_arguments_named(robot):
    z = np.zeros(robot.nq)
    with pytest.raises(ValueError, match="ddq"):
        extwrench.rnea(robot, z, z, np.zeros(2))
    with pytest.raises(ValueError, match="body"):
        extwrench.jacobian(robot, z, 99)
    with pytest.raises(ValueError, match="no body or frame named 'nope'"):
        extwrench.jacobian(robot, z, "nope")
    with pytest.raises(ValueError, match="point_W"):
        extwrench.jacobian(robot, z, 3, [0.0, 1.0])
    with pytest.raises(ValueError, match="X_WS"):
        extwrench.sensor_reading(robot, z, z, z, X_WS=np.ones((4, 4)))
    with pytest.raises(TypeError, match="wrenches"):
        extwrench.rnea(robot, z, z, z, [1, 2])


TWO_LINKS_AND_A_TIP = """<robot name="two">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="upper"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="lower"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="tip"/>
  <joint name="j1" type="continuous"><parent link="base"/><child link="upper"/><axis xyz="0 1 0"/></joint>
  <joint name="j2" type="continuous"><parent link="upper"/><child link="lower"/>
    <origin xyz="0 0 0.4"/><axis xyz="1 0 0"/></joint>
  <joint name="t" type="fixed"><parent link="lower"/><child link="tip"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.3 0 0"/></joint>
</robot>
"""


def test_jacobian_of_a_frame_is_at_the_frame(tmp_path):
    # A frame merged into its body (a tool tip): J_v is the velocity of the frame's origin,
    # checked against finite differences of forward_kinematics, not the body origin's.
    path = tmp_path / "two.urdf"
    path.write_text(TWO_LINKS_AND_A_TIP)
    robot = extwrench.load_robot(path)
    lower = robot.bodies.index("lower")
    q = np.array([0.4, -0.7])

    def tip(q):
        return (extwrench.forward_kinematics(robot, q)[lower] @ [0.1, 0.2, 0.3, 1.0])[:3]

    h = 1e-6
    fd = np.column_stack([(tip(q + h * e) - tip(q - h * e)) / (2 * h) for e in np.eye(2)])
    J = extwrench.jacobian(robot, q, "tip")
    np.testing.assert_allclose(J[:3], fd, atol=1e-8)
    assert np.abs(J[:3] - extwrench.jacobian(robot, q, "lower")[:3]).max() > 0.1
    # An index from an estimate's `link` column is a numpy integer.
    assert np.array_equal(extwrench.jacobian(robot, q, np.int64(lower)),
                          extwrench.jacobian(robot, q, lower))
    with pytest.raises(TypeError, match="body index"):
        extwrench.jacobian(robot, q, True)


def test_frame_pose_is_the_frames_placement_on_its_body(tmp_path):
    # Pinocchio's oMf, which Python lacked (a review): the tip frame's pose is its body's pose
    # times the URDF's fixed origin (xyz 0.1 0.2 0.3, rpy 0.3 0 0), its rotation a rotation, and
    # its origin moves as jacobian(robot, q, 'tip') says (finite differences).
    path = tmp_path / "two.urdf"
    path.write_text(TWO_LINKS_AND_A_TIP)
    robot = extwrench.load_robot(path)
    lower = robot.bodies.index("lower")
    q, dq = np.array([0.4, -0.7]), np.array([0.3, -0.5])
    c, s = np.cos(0.3), np.sin(0.3)
    placement = np.array([[1, 0, 0, 0.1], [0, c, -s, 0.2], [0, s, c, 0.3], [0, 0, 0, 1.0]])
    X = extwrench.frame_pose(robot, q, "tip")
    np.testing.assert_allclose(X, extwrench.forward_kinematics(robot, q)[lower] @ placement,
                               atol=1e-15)
    np.testing.assert_allclose(X[:3, :3] @ X[:3, :3].T, np.eye(3), atol=1e-15)
    h = 1e-6
    velocity = (extwrench.frame_pose(robot, q + h * dq, "tip")[:3, 3]
                - extwrench.frame_pose(robot, q - h * dq, "tip")[:3, 3]) / (2 * h)
    np.testing.assert_allclose(extwrench.jacobian(robot, q, "tip")[:3] @ dq, velocity, atol=1e-8)
    # A body by name or index is its body pose.
    np.testing.assert_array_equal(extwrench.frame_pose(robot, q, "lower"),
                                  extwrench.forward_kinematics(robot, q)[lower])
    np.testing.assert_array_equal(extwrench.frame_pose(robot, q, np.int64(lower)),
                                  extwrench.frame_pose(robot, q, "lower"))
    with pytest.raises(ValueError, match="no body or frame named 'nope'"):
        extwrench.frame_pose(robot, q, "nope")
    with pytest.raises(ValueError, match="q"):
        extwrench.frame_pose(robot, q[:1], "tip")


def test_no_reference_leak_over_many_calls(robot):
    n = robot.nq
    q, dq, ddq = np.zeros(n), np.full(n, 0.1), np.zeros(n)
    w = [extwrench.ExternalWrench(3, [1.0, 2.0, 3.0])]
    before = [sys.getrefcount(x) for x in (q, dq, ddq, w[0], robot)]
    for _ in range(20000):
        extwrench.rnea(robot, q, dq, ddq, w)
        extwrench.crba(robot, q)
        extwrench.forward_kinematics(robot, q)
        try:
            extwrench.rnea(robot, q, dq, np.zeros(2))
        except ValueError:
            pass
    gc.collect()
    assert [sys.getrefcount(x) for x in (q, dq, ddq, w[0], robot)] == before
    # The results are owned by Python: a returned array dies with its last reference.
    import weakref
    r = extwrench.rnea(robot, q, dq, ddq)
    base = r.base if r.base is not None else r
    ref = weakref.ref(base) if hasattr(base, "__weakref__") else None
    del r, base
    gc.collect()
    if ref is not None:
        assert ref() is None


def test_memory_does_not_grow(robot):
    import tracemalloc
    n = robot.nq
    q = np.zeros(n)
    for _ in range(1000):
        extwrench.rnea(robot, q, q, q)
    tracemalloc.start()
    snap0 = tracemalloc.take_snapshot()
    for _ in range(50000):
        extwrench.rnea(robot, q, q, q)
        extwrench.jacobian(robot, q, 5)
    snap1 = tracemalloc.take_snapshot()
    tracemalloc.stop()
    growth = sum(s.size_diff for s in snap1.compare_to(snap0, "filename"))
    assert growth < 100_000, growth
