"""Meshes and chains from Python: closest points against analytic answers (a box), batched over
an N×3 array, and forward and inverse kinematics of a URDF chain against a hand computation."""

import math

import numpy as np
import pytest

import hapsim

HALF = np.array([0.05, 0.03, 0.02])  # builtin:box is 100 x 60 x 40 mm about the origin


def box_signed_distance(p):
    q = np.abs(p) - HALF
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    inside = np.minimum(q.max(axis=1), 0.0)
    return outside + inside


def test_closest_on_a_box_matches_the_analytic_distance():
    mesh = hapsim.load_mesh("builtin:box")
    assert mesh.vertices.shape == (8, 3) and mesh.vertices.dtype == np.float64
    assert mesh.triangles.shape == (12, 3) and mesh.triangles.dtype == np.uint32
    rng = np.random.default_rng(7)
    points = rng.uniform(-0.1, 0.1, size=(2000, 3))
    for method in ("exact", "spheretree"):
        r = mesh.closest(points, method=method)
        assert r["signed_distance"].shape == (2000,) and r["point"].shape == (2000, 3)
        assert r["normal"].shape == (2000, 3) and r["triangle"].dtype == np.int64
        np.testing.assert_allclose(r["signed_distance"], box_signed_distance(points), atol=1e-12)
        # The closest point lies on the box's surface, at the reported distance.
        np.testing.assert_allclose(np.abs(r["point"]).max(axis=0) <= HALF + 1e-12, True)
        np.testing.assert_allclose(np.linalg.norm(points - r["point"], axis=1),
                                   np.abs(r["signed_distance"]), atol=1e-12)


def test_closest_refuses_a_point_that_is_not_finite():
    # A NaN point once crashed the interpreter inside the tree's traversal.
    mesh = hapsim.load_mesh("builtin:box")
    for bad in (np.nan, np.inf, -np.inf):
        points = np.zeros((3, 3))
        points[1, 2] = bad
        for method in ("exact", "spheretree"):
            with pytest.raises(hapsim.Error, match="row 1 is not finite"):
                mesh.closest(points, method=method)
    # Absurdly far but finite (past 1e15 m): no closest point (triangle -1), never a crash.
    r = mesh.closest(np.array([[1e300, 0.0, 0.0], [0.0, 0.0, 1e19], [0.0, 0.0, 1.0]]))
    assert list(r["triangle"][:2]) == [-1, -1] and r["triangle"][2] >= 0
    assert abs(r["signed_distance"][2] - 0.98) < 1e-12  # the builtin box: 20 mm half height


def test_closest_refuses_a_bad_shape_and_method():
    mesh = hapsim.load_mesh("builtin:box")
    with pytest.raises(hapsim.Error, match="N×3"):
        mesh.closest(np.zeros((4, 2)))
    with pytest.raises(hapsim.Error, match="method"):
        mesh.closest(np.zeros((4, 3)), method="fastest")
    with pytest.raises(hapsim.Error, match="unknown built-in"):
        hapsim.load_mesh("builtin:teapot")


PLANAR_URDF = """<robot name="planar">
  <link name="base"/><link name="upper"/><link name="lower"/><link name="tip"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="wrist" type="fixed"><parent link="lower"/><child link="tip"/>
    <origin xyz="0.2 0 0"/></joint>
</robot>
"""


def test_forward_and_inverse_kinematics_of_a_planar_arm(tmp_path):
    urdf = tmp_path / "planar.urdf"
    urdf.write_text(PLANAR_URDF)
    chain = hapsim.load_chain(str(urdf))
    assert chain.dof == 2 and chain.joint_names == ["shoulder", "elbow"]
    assert chain.limits.shape == (2, 2)
    q1, q2 = 0.4, -0.9
    X = chain.forward([q1, q2])
    assert X.shape == (4, 4)
    expected = [0.3 * math.cos(q1) + 0.2 * math.cos(q1 + q2),
                0.3 * math.sin(q1) + 0.2 * math.sin(q1 + q2), 0.1]
    np.testing.assert_allclose(X[:3, 3], expected, atol=1e-12)
    rows = np.array([[q1, q2], [0.0, 0.0], [1.0, 1.0]])
    batch = chain.forward(rows)
    assert batch.shape == (3, 4, 4)
    np.testing.assert_allclose(batch[0], X, atol=1e-15)
    np.testing.assert_allclose(batch[1][:3, 3], [0.5, 0.0, 0.1], atol=1e-12)
    answer = chain.inverse(X, seed=[0.1, -0.5], orientation=False)
    assert answer["reached"] and answer["position_error_m"] < 1e-4
    np.testing.assert_allclose(chain.forward(answer["q"])[:3, 3], expected, atol=1e-4)
