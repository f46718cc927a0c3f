"""FEM bodies and tet meshes from Python: scenes/fem_block.json pressed in the middle of its top by
a probe stepped from Python (node positions, displacements, fixed nodes and stresses as arrays:
shapes, dtypes, frames, and where the block gave way), the FEM figures against `hapsim run`'s, a
Gmsh file written here read back against its known content, generated blocks, and bad names and
bad meshes refused by name."""

import ast

import numpy as np
import pytest

import hapsim
from conftest import ROOT, SCENES

FEM_BLOCK = SCENES / "fem_block.json"
# The block: 80 x 60 x 30 mm, 16 x 12 x 6 cells (5 mm), its body frame at (-40, -30, 0) mm, so
# in the world it spans x ±40 mm, y ±30 mm, z 0..30 mm, its bottom held by the table (z = 0).
HALF_X, HALF_Y, TOP_Z = 0.04, 0.03, 0.03
TOOL_RADIUS = 0.005
DEPTH = 0.006
PRESS_STEPS, HOLD_STEPS = 800, 400


@pytest.fixture(scope="module")
def pressed():
    """The block after a 5 mm fingertip came straight down on the middle of its top, 6 mm into
    it (0.8 s), and held there (0.4 s), stepped from Python."""
    world = hapsim.World(str(FEM_BLOCK))
    for i in range(PRESS_STEPS + HOLD_STEPS):
        depth = DEPTH * min(i / PRESS_STEPS, 1.0)
        world.step(hapsim.DeviceInput(p_world=[0.0, 0.0, TOP_Z + TOOL_RADIUS - depth]))
    return world


def test_fem_bodies_lists_the_block():
    world = hapsim.World(str(FEM_BLOCK))
    (block,) = world.fem_bodies()
    assert block["name"] == "block" and block["body"] == world.body_names.index("block")
    # 6 tets per cell, (16+1)(12+1)(6+1) nodes; the bottom layer is held by the table.
    assert block["tets"] == 6 * 16 * 12 * 6 and block["nodes"] == 17 * 13 * 7
    assert block["fixed_nodes"] == 17 * 13
    assert block["elasticity"] == "corotational" and block["integration"] == "backward_euler"
    assert block["dt_s"] == pytest.approx(0.01)
    assert block["mass_kg"] == pytest.approx(1000.0 * 0.08 * 0.06 * 0.03, rel=1e-9)


def test_arrays_have_their_shapes_dtypes_and_frame(pressed):
    n, t = 17 * 13 * 7, 6 * 16 * 12 * 6
    x = pressed.fem_node_positions("block")
    rest = pressed.fem_rest_nodes("block")
    u = pressed.fem_displacement("block")
    for a in (x, rest, u):
        assert a.shape == (n, 3) and a.dtype == np.float64
    tets = pressed.fem_tets("block")
    assert tets.shape == (t, 4) and tets.dtype == np.uint32 and tets.max() == n - 1
    regions = pressed.fem_regions("block")
    assert regions.shape == (t,) and regions.dtype == np.int32 and not regions.any()
    fixed = pressed.fem_fixed_nodes("block")
    assert fixed.shape == (n,) and fixed.dtype == np.bool_
    assert pressed.fem_von_mises_pa("block").shape == (t,)
    stress = pressed.fem_stress_pa("block")
    assert stress.shape == (t, 3, 3) and stress.dtype == np.float64
    # By name or by index, the same body; copies, so they can be written.
    np.testing.assert_array_equal(pressed.fem_node_positions(1), x)
    x[:] = 0.0
    assert pressed.fem_node_positions("block").any()
    # The world frame: the rest block where the scene puts it, each tet positively oriented.
    np.testing.assert_allclose(rest.min(axis=0), [-HALF_X, -HALF_Y, 0.0], atol=1e-15)
    np.testing.assert_allclose(rest.max(axis=0), [HALF_X, HALF_Y, TOP_Z], atol=1e-15)
    p = rest[tets.astype(np.int64)]
    volumes = np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0],
                                                                 p[:, 3] - p[:, 0])) / 6.0
    assert volumes.min() > 0.0
    assert volumes.sum() == pytest.approx(2 * HALF_X * 2 * HALF_Y * TOP_Z, rel=1e-12)
    np.testing.assert_allclose(pressed.fem_node_positions("block"), rest + u, atol=1e-15)


def test_the_top_gives_way_under_the_probe_and_the_held_bottom_does_not(pressed):
    rest = pressed.fem_rest_nodes("block")
    x = pressed.fem_node_positions("block")
    u = pressed.fem_displacement("block")
    fixed = pressed.fem_fixed_nodes("block")
    # Held: exactly the nodes the table touches, not moved at all.
    np.testing.assert_array_equal(fixed, rest[:, 2] == 0.0)
    np.testing.assert_array_equal(x[fixed], rest[fixed])
    assert not u[fixed].any()
    top = np.isclose(rest[:, 2], TOP_Z, rtol=0.0, atol=1e-12)
    r = np.linalg.norm(rest[:, :2], axis=1)
    under = top & (r <= TOOL_RADIUS + 1e-9)
    assert under.sum() == 5  # the centre node and its 4 neighbours on the 5 mm grid
    centre = top & (r < 1e-9)
    # The top centre went down millimetres (the tool is 6 mm in: about that, the load spread
    # over the contact patch dents the centre a little deeper than the patch's mean), the nodes
    # under the tool too, and the lowest top node is under the tool.
    assert -1.5 * DEPTH < u[centre, 2][0] < -0.5 * DEPTH
    assert (u[under, 2] < -0.0015).all()
    lowest = np.flatnonzero(top)[np.argmin(x[top, 2])]
    assert r[lowest] <= TOOL_RADIUS + 1e-9
    # Far from the tool (the top's edges) the surface hardly moved; the dent fades with distance.
    edge = top & (r > 0.03)
    assert np.abs(u[edge, 2]).max() < 0.05 * abs(u[centre, 2][0])
    ring = top & np.isclose(r, 0.01, atol=1e-9)
    assert u[centre, 2][0] < u[ring, 2].max() < 0.0
    # The probe feels the block push back up.
    assert pressed.force_world_n[2] > 0.3


def test_von_mises_is_largest_under_the_probe(pressed):
    vm = pressed.fem_von_mises_pa("block")
    assert np.isfinite(vm).all() and (vm >= 0.0).all()
    rest = pressed.fem_rest_nodes("block")
    centroid = rest[pressed.fem_tets("block").astype(np.int64)].mean(axis=1)
    peak = centroid[np.argmax(vm)]
    assert np.linalg.norm(peak[:2]) < TOOL_RADIUS and peak[2] > TOP_Z / 2
    far = np.linalg.norm(centroid[:, :2], axis=1) > 0.03
    assert vm[far].max() < 0.1 * vm.max()
    # The stress tensors are symmetric and give the same von Mises stress (a frame change keeps it).
    s = pressed.fem_stress_pa("block")
    np.testing.assert_allclose(s, s.transpose(0, 2, 1), atol=1e-9 * vm.max())
    dev = s - np.trace(s, axis1=1, axis2=2)[:, None, None] / 3.0 * np.eye(3)
    np.testing.assert_allclose(np.sqrt(1.5 * (dev * dev).sum(axis=(1, 2))), vm,
                               atol=1e-9 * vm.max())
    e = pressed.fem_energies("block")
    assert e["elastic_j"] > 0.0 and e["kinetic_j"] >= 0.0


def test_the_drawn_surface_is_the_nodes_now(pressed):
    """World.surface() of a FEM body (body frame) is its boundary nodes where they are now."""
    body = pressed.body_names.index("block")
    vertices, _ = pressed.surface(body, 0)
    X = pressed.body_pose(body)
    world = vertices @ X[:3, :3].T + X[:3, 3]
    x = pressed.fem_node_positions("block")
    # Each surface vertex is one of the nodes (the dent included).
    d2 = ((world[:, None, :] - x[None, :, :]) ** 2).sum(axis=2)
    assert np.sqrt(d2.min(axis=1)).max() < 1e-12
    assert world[:, 2].min() == pytest.approx(0.0, abs=1e-15)
    assert world[:, 2].max() == pytest.approx(TOP_Z, abs=1e-4)


def test_fem_stats_count_the_updates_as_a_run_does(pressed):
    stats = pressed.fem_stats()
    steps = PRESS_STEPS + HOLD_STEPS
    assert stats["period_steps"] == 10  # 10 ms FEM step, 1 ms haptic step
    assert stats["updates"] == steps // 10
    assert stats["adopted"] == stats["updates"] - 1  # the last one is due a period later
    assert stats["late_adopted"] == 0 and stats["skipped_launches"] == 0
    assert stats["failures"] == 0
    assert stats["update_ms"]["max"] >= stats["update_ms"]["p50"] > 0.0
    (body,) = stats["bodies"]
    assert body["name"] == "block"
    u = pressed.fem_displacement("block")
    assert body["final_max_displacement_m"] == pytest.approx(np.linalg.norm(u, axis=1).max(),
                                                             rel=1e-12)
    # The same object as `hapsim run --json`'s "fem" (run() gives that dict).
    summary = hapsim.run(str(FEM_BLOCK), duration=0.05)
    assert set(summary["fem"]) == set(stats)
    assert set(summary["fem"]["bodies"][0]) == set(body)


def test_reset_brings_the_block_back_to_rest():
    world = hapsim.World(str(FEM_BLOCK))
    for i in range(300):
        world.step(hapsim.DeviceInput(p_world=[0.0, 0.0, TOP_Z + TOOL_RADIUS - 0.004 * i / 300]))
    assert world.fem_displacement("block")[:, 2].min() < -0.001
    world.reset()
    assert not world.fem_displacement("block").any()
    np.testing.assert_array_equal(world.fem_node_positions("block"), world.fem_rest_nodes(1))


def test_a_body_that_is_not_a_fem_body_is_refused_by_name():
    world = hapsim.World(str(FEM_BLOCK))
    with pytest.raises(hapsim.Error, match="no FEM body 'liver'.*block \\(body 1\\)") as e:
        world.fem_node_positions("liver")
    assert e.value.where == "body"
    with pytest.raises(hapsim.Error, match="body 0 \\('table'\\) is not a FEM body"):
        world.fem_von_mises_pa("table")
    with pytest.raises(hapsim.Error, match="is not a FEM body"):
        world.fem_tets(np.int64(0))
    with pytest.raises(IndexError, match="no body 5"):
        world.fem_stress_pa(5)
    with pytest.raises(hapsim.Error, match="name or index"):
        world.fem_fixed_nodes(1.0)
    # A world without FEM bodies says so.
    knee = hapsim.World(str(SCENES / "knee_procedural.json"))
    assert knee.fem_bodies() == [] and knee.fem_stats() is None
    with pytest.raises(hapsim.Error, match="the world has no FEM body"):
        knee.fem_displacement(0)


# Gmsh 4.1: two tets sharing a face, in volumes 1 and 2 of physical groups 11 and 22, node tags
# 10..50 in two blocks, a triangle block the reader skips. Node tags 10, 20, 30, 40, 50 hold
# (1,0,0), (0,0,0), (0,1,0), (0,0,1), (1,1,1): the tets are (0,0,0)-(1,0,0)-(0,1,0)-(0,0,1)
# (volume 1/6) and (1,0,0)-(0,1,0)-(0,0,1)-(1,1,1) (volume 1/3).
TWO_TET_MSH = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
3 11 "soft"
3 22 "hard"
$EndPhysicalNames
$Entities
0 0 1 2
5 0 0 0 1 1 0 0 0
1 0 0 0 1 1 1 1 11 0
2 0 0 0 1 1 1 1 22 0
$EndEntities
$Nodes
2 5 10 50
3 1 0 3
10
20
30
1 0 0
0 0 0
0 1 0
3 2 0 2
40
50
0 0 1
1 1 1
$EndNodes
$Elements
3 4 1 4
2 5 2 2
1 20 30 40
2 30 50 40
3 1 4 1
3 20 10 30 40
3 2 4 1
4 10 30 40 50
$EndElements
"""


def test_read_tet_mesh_reads_a_gmsh_file(tmp_path):
    path = tmp_path / "two.msh"
    path.write_text(TWO_TET_MSH)
    mesh = hapsim.read_tet_mesh(path)
    assert mesh.node_count == 5 and mesh.tet_count == 2 and mesh.source == str(path)
    assert mesh.nodes.dtype == np.float64 and not mesh.nodes.flags.writeable
    np.testing.assert_array_equal(mesh.nodes, [[1, 0, 0], [0, 0, 0], [0, 1, 0], [0, 0, 1],
                                               [1, 1, 1]])
    assert mesh.tets.dtype == np.uint32
    np.testing.assert_array_equal(mesh.tets, [[1, 0, 2, 3], [0, 2, 3, 4]])
    assert mesh.regions.dtype == np.int32 and mesh.regions.tolist() == [11, 22]
    assert mesh.volume_m3 == pytest.approx(0.5, abs=1e-15)
    q = hapsim.tet_mesh_quality(mesh)
    assert q == mesh.quality()
    assert q["tets"] == 2 and q["nodes"] == 5 and q["components"] == 1
    assert q["inverted"] == q["degenerate"] == q["unused_nodes"] == 0
    assert q["total_volume_m3"] == pytest.approx(0.5, abs=1e-15)
    assert q["min_volume_m3"] == pytest.approx(1.0 / 6.0, abs=1e-15)
    # The corner tet's right angles: its dihedral angles run from 54.7° (arccos(1/√3)) to 90°.
    assert q["min_dihedral_deg"] == pytest.approx(np.degrees(np.arccos(1 / np.sqrt(3))), abs=1e-9)
    assert q["max_dihedral_deg"] == pytest.approx(90.0, abs=1e-9)
    vertices, triangles, node = mesh.boundary()
    assert triangles.shape == (6, 3) and vertices.shape == (5, 3)  # the shared face is inside
    np.testing.assert_array_equal(vertices, mesh.nodes[node])
    # In millimetres: scaled to metres.
    mm = hapsim.read_tet_mesh(str(path), scale=1e-3)
    np.testing.assert_allclose(mm.nodes, mesh.nodes * 1e-3, rtol=1e-15)


def test_bad_tet_meshes_are_refused_naming_file_and_element(tmp_path):
    # The second tet turned inside out (the first as in the file): line 38, element 1.
    bad = tmp_path / "inverted.msh"
    bad.write_text(TWO_TET_MSH.replace("4 10 30 40 50", "4 30 10 40 50"))
    with pytest.raises(hapsim.Error, match="inverted.msh:38: element 1: inverted"):
        hapsim.read_tet_mesh(bad)
    with pytest.raises(hapsim.Error, match="missing.msh"):
        hapsim.read_tet_mesh(tmp_path / "missing.msh")
    text = tmp_path / "mesh.txt"
    text.write_text("not a mesh")
    with pytest.raises(hapsim.Error):
        hapsim.read_tet_mesh(text)
    with pytest.raises(hapsim.Error, match="scale"):
        hapsim.read_tet_mesh(bad, scale=0.0)


def test_tet_mesh_from_arrays_is_measured_and_validated():
    nodes = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    good = hapsim.TetMesh(nodes, [[0, 1, 2, 3]], regions=np.array([7]))
    assert good.regions.tolist() == [7] and good.volume_m3 == pytest.approx(1.0 / 6.0)
    good.validate()
    inverted = hapsim.TetMesh(nodes, np.array([[1, 0, 2, 3]], dtype=np.uint32))
    assert inverted.regions.tolist() == [0]
    assert inverted.quality()["inverted"] == 1
    with pytest.raises(hapsim.Error, match="element 0: inverted"):
        inverted.validate()
    out_of_range = hapsim.TetMesh(nodes, [[0, 1, 2, 9]])
    assert out_of_range.quality()["out_of_range"] == 1
    with pytest.raises(hapsim.Error, match="element 0"):
        out_of_range.validate()
    with pytest.raises(hapsim.Error, match="tets"):
        hapsim.TetMesh(nodes, [[0, 1, 2]])
    with pytest.raises(hapsim.Error, match="tets"):
        hapsim.TetMesh(nodes, [[0, 1, 2, -1]])
    with pytest.raises(hapsim.Error, match="tets"):
        hapsim.TetMesh(nodes, [[0.0, 1.5, 2.0, 3.0]])
    with pytest.raises(hapsim.Error, match="regions"):
        hapsim.TetMesh(nodes, [[0, 1, 2, 3]], regions=[1, 2])
    with pytest.raises(hapsim.Error, match="nodes"):
        hapsim.TetMesh(nodes[:, :2], [[0, 1, 2, 3]])


def test_make_tet_block_fills_the_box():
    block = hapsim.make_tet_block([0.02, 0.03, 0.01], [2, 3, 1], origin_m=[1.0, 0.0, -0.01])
    assert block.tet_count == 6 * 2 * 3 * 1 and block.node_count == 3 * 4 * 2
    np.testing.assert_allclose(block.nodes.min(axis=0), [1.0, 0.0, -0.01], atol=1e-15)
    np.testing.assert_allclose(block.nodes.max(axis=0), [1.02, 0.03, 0.0], atol=1e-15)
    q = block.quality()
    assert q["inverted"] == q["degenerate"] == 0 and q["components"] == 1
    assert q["total_volume_m3"] == pytest.approx(0.02 * 0.03 * 0.01, rel=1e-12)
    block.validate()
    with pytest.raises(hapsim.Error, match="cells"):
        hapsim.make_tet_block([0.01, 0.01, 0.01], [0, 1, 1])
    with pytest.raises(hapsim.Error, match="cells"):
        hapsim.make_tet_block([0.01, 0.01, 0.01], [1.5, 1, 1])
    with pytest.raises(hapsim.Error, match="2 million"):
        hapsim.make_tet_block([1.0, 1.0, 1.0], [200, 200, 200])
    with pytest.raises(hapsim.Error, match="size_m"):
        hapsim.make_tet_block([0.01, -0.01, 0.01], [1, 1, 1])


def test_the_type_stubs_declare_the_fem_api():
    """_hapsim.pyi declares every FEM method and function the module has."""
    tree = ast.parse((ROOT / "python" / "hapsim" / "_hapsim.pyi").read_text())
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    functions = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}

    def members(cls):
        return {n.name for n in cls.body if isinstance(n, ast.FunctionDef)}

    world_fem = {name for name in dir(hapsim.World) if name.startswith("fem_")}
    assert world_fem and world_fem <= members(classes["World"])
    tet_public = {name for name in dir(hapsim.TetMesh) if not name.startswith("_")}
    assert tet_public <= members(classes["TetMesh"])
    assert {"read_tet_mesh", "make_tet_block", "tet_mesh_quality"} <= functions
    for name in ("TetMesh", "read_tet_mesh", "make_tet_block", "tet_mesh_quality"):
        assert name in hapsim.__all__
