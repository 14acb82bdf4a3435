"""`mesoforge sdf`: trace an implicit medium to a PNG, voxelise it to a mesh or .npy; refusals
before any work or file."""

import json

import numpy as np
import pytest

from app import cli
from engine.graph import AddNode, Connect, GraphDocument, UndoStack
from engine.graph.project import save_project


def _run(capsys, *args):
    code = cli.main(["sdf", *map(str, args)])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


@pytest.fixture
def project(tmp_path):
    doc = GraphDocument()
    st = UndoStack(doc)
    st.push(AddNode("PeriodicFunction", {"kind": "gyroid", "cell": 0.5, "level_by": "level", "level": 0.0},
                    node_id="g"))
    st.push(AddNode("Particles", {"cell": 0.25, "size_a": 0.03, "size_b": 0.08, "seed": 3}, node_id="p"))
    st.push(AddNode("SDFBoolean", {"operation": "union"}, node_id="u"))
    st.push(Connect("g", "sdf", "u", "a"))
    st.push(Connect("p", "sdf", "u", "b"))
    st.push(AddNode("Vertex", node_id="v"))                    # not an SDF node
    path = tmp_path / "media.json"
    save_project(doc, path)
    return path


def test_render_writes_the_traced_png_and_reports_the_frame(project, tmp_path, capsys):
    from PIL import Image

    png = tmp_path / "view.png"
    code, out, err = _run(capsys, project, "--render", png, "--size", "96x64", "--step", "bijection", "--json")
    assert code == 0, err
    info = json.loads(out)
    assert info["node"] == "u" and info["size"] == [96, 64] and info["step"] == "bijection"
    assert info["frame_ms"] > 0 and 1 <= info["mean_steps"] <= info["max_steps"]
    img = np.asarray(Image.open(png))
    assert img.shape == (64, 96, 4)
    assert 0.1 < info["hit_fraction"] < 1.0                      # the cube of medium, background around it
    assert (img[..., 3] > 0).mean() == pytest.approx(info["hit_fraction"], abs=0.02)
    cam = [float(v) for v in info["camera"].split(",")]
    assert cam[3:6] == [0.5, 0.5, 0.5] and cam[6] == 40.0         # framing the default [0, 1]^3 view box


def test_a_given_camera_and_node_are_used(project, tmp_path, capsys):
    png = tmp_path / "g.png"
    code, out, err = _run(capsys, project, "--render", png, "--size", "32x32", "--node", "g",
                          "--camera", "3,0.5,0.5,0.5,0.5,0.5,30", "--view-box", "0,0,0,1,1,1", "--json")
    assert code == 0, err
    info = json.loads(out)
    assert info["node"] == "g" and info["camera"] == "3.0,0.5,0.5,0.5,0.5,0.5,30.0"


def test_paths_accumulate_a_path_traced_picture(project, tmp_path, capsys):
    from PIL import Image

    png = tmp_path / "pt.png"
    code, out, err = _run(capsys, project, "--render", png, "--size", "32x24", "--paths", 3, "--max-depth", 4,
                          "--json")
    assert code == 0, err
    info = json.loads(out)
    assert info["frames"] == 3 and len(info["frame_ms"]) == 3 and 0 < info["mean_depth"] <= 4
    assert np.asarray(Image.open(png)).shape == (24, 32, 4)


def test_voxels_write_a_closed_mesh_and_the_npy_node_samples(project, tmp_path, capsys):
    import trimesh

    stl = tmp_path / "m.stl"
    code, out, err = _run(capsys, project, "--voxels", 48, "--out", stl, "--json")
    assert code == 0, err
    info = json.loads(out)
    assert info["grid"] == [48, 48, 48] and info["watertight"]
    assert trimesh.load(stl).is_watertight
    npy = tmp_path / "g.npy"
    code, out, err = _run(capsys, project, "--voxels", 32, "--out", npy, "--node", "g", "--box-from", "0,0,0",
                          "--box-to", "1,1,0.5", "--json")
    assert code == 0, err
    info = json.loads(out)
    d = np.load(npy)
    assert d.shape == (32, 32, 16) and info["box"] == [[0, 0, 0], [1, 1, 0.5]]
    i, j, k = 5, 17, 9                                         # node (i, j, k) at box_from + i * edge / N
    x, y, z = (2 * np.pi / 0.5) * np.array([i / 32, j / 32, k * 0.5 / 16])
    gyroid = np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x)
    from engine.implicit.periodic import Periodic
    assert d[i, j, k] == pytest.approx(gyroid / Periodic("gyroid", cell=0.5).lipschitz, abs=1e-5)


@pytest.mark.parametrize("args, message", [
    (["--render", "x.png", "--voxels", "16"], "exactly one of"),
    (["--render", "x.txt"], "--render"),
    (["--render", "x.png", "--size", "10x10"], "--size"),
    (["--render", "x.png", "--step", "huge"], "--step"),
    (["--render", "x.png", "--camera", "1,2,3"], "--camera"),
    (["--render", "x.png", "--node", "v"], "has no SDF output"),
    (["--render", "x.png", "--node", "nope"], "no such node"),
    (["--voxels", "4", "--out", "m.stl"], "--voxels"),
    (["--voxels", "16"], "--out"),
    (["--voxels", "16", "--out", "m.stl", "--box-from", "0,0,0", "--box-to", "1,0,1"], "--box-to"),
])
def test_bad_flags_are_refused_before_any_file(project, tmp_path, capsys, args, message, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = _run(capsys, project, *args)
    assert code == 2 and message in err and err.count("\n") == 1, err
    assert not (tmp_path / "x.png").exists() and not (tmp_path / "m.stl").exists()


def test_a_node_that_fails_on_valid_flags_exits_1(tmp_path, capsys):
    doc = GraphDocument()
    UndoStack(doc).push(AddNode("Particles", {"cell": 1.0, "density": 0.0}, node_id="p"))
    path = tmp_path / "empty.json"
    save_project(doc, path)
    code, out, err = _run(capsys, path, "--voxels", 16, "--out", tmp_path / "m.stl")
    assert code == 1 and "nothing of the medium" in err and not (tmp_path / "m.stl").exists()
