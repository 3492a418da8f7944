"""The Python package against clayc: the same session through both gives the same summary;
diagnostics, errors, parameters, arrays, exports and pictures."""

import json
import math
import os
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

import clay


def clayc_summary(clayc: str, grammar: Path, script: Path | None, *settings: str) -> dict:
    args = [clayc, "run", str(grammar), "--json"]
    if script is not None:
        args += ["--script", str(script)]
    for s in settings:
        args += ["--set", s]
    out = subprocess.run(args, capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def without_times(summary: dict) -> dict:
    """Frame times vary from run to run; everything else is deterministic."""
    return {k: v for k, v in summary.items() if k != "frame_ms"}


# --- the same session through Python and through clayc run ------------------------------


def test_the_wall_script_as_calls_gives_clayc_runs_summary(clayc, grammars):
    expected = clayc_summary(clayc, grammars / "wall.clay", grammars / "wall.script.json")
    s = clay.Session(clay.Grammar.open(grammars / "wall.clay"))
    s.pin(extreme="west")
    s.grab(extreme="east")
    s.drag(by=(8, 0), frames=120)
    s.hold(frames=30)
    s.drag(by=(-8, 0), frames=120)
    s.hold(frames=30)
    got = s.summary()
    assert without_times(got) == without_times(expected)
    assert set(got["frame_ms"]) == {"median", "max"}
    assert s.frames == expected["frames"] == 300


@pytest.mark.parametrize("name", ["castle", "junction", "centipede"])
def test_every_scripted_example_run_from_python_gives_clayc_runs_summary(clayc, grammars, name):
    grammar, script = grammars / f"{name}.clay", grammars / f"{name}.script.json"
    expected = clayc_summary(clayc, grammar, script)
    s = clay.Session(clay.Grammar.open(grammar))
    s.run_script(script)
    assert without_times(s.summary()) == without_times(expected)
    # The same script as a dict.
    d = clay.Session(clay.Grammar.open(grammar))
    d.run_script(json.loads(script.read_text()))
    assert without_times(d.summary()) == without_times(expected)


def test_solver_settings_are_clayc_runs_set(clayc, grammars):
    expected = clayc_summary(
        clayc, grammars / "wall.clay", grammars / "wall.script.json", "norm=2", "solver=cg"
    )
    s = clay.Session(clay.Grammar.open(grammars / "wall.clay"), norm=2, solver="cg")
    assert s.solver["norm"] == 2.0
    s.run_script(grammars / "wall.script.json")
    assert without_times(s.summary()) == without_times(expected)


def test_the_initial_summary_is_clayc_runs_without_a_script(clayc, grammars):
    expected = clayc_summary(clayc, grammars / "castle.clay", None)
    s = clay.Session(clay.Grammar.open(grammars / "castle.clay"))
    assert without_times(s.summary()) == without_times(expected)


def test_a_pulled_wall_grows_and_the_rule_log_says_how(grammars):
    s = clay.Session(clay.Grammar.open(grammars / "wall.clay"))
    s.pin(extreme="west")
    s.grab(extreme="east")
    s.drag(by=(8, 0), frames=120)
    s.hold(frames=30)
    assert s.summary()["pieces"] == {"brick": 16}
    kinds = {e.kind for e in s.rule_log}
    assert "stretch" in kinds
    stretch = next(e for e in s.rule_log if e.kind == "stretch")
    assert "brick" in stretch.detail or "wall" in stretch.detail
    assert all(math.isfinite(c) for c in stretch.at)
    assert len(s.instances) == 16
    events = s.frame()
    assert all(isinstance(e, clay.RuleEvent) for e in events)
    assert s.frames == 151


# --- diagnostics ---------------------------------------------------------------------------


def test_check_gives_diagnostics_with_positions(root):
    fixture = root / "tests/fixtures/invalid/E011-unknown-piece.clay"
    diags = clay.check(fixture)
    assert len(diags) == 1
    d = diags[0]
    assert (d.code, d.severity, d.line, d.column) == ("E011", "error", 18, 18)
    assert (d.end_line, d.end_column) == (18, 22)
    assert d.path == str(fixture)
    assert "unknown piece `brik`" in d.message
    assert any("brick" in h for h in d.hints)
    assert str(d).startswith(f"{fixture}:18:18: error[E011]")


def test_clean_grammars_check_clean(grammars):
    for g in sorted(grammars.glob("*.clay")):
        assert [d for d in clay.check(g) if d.severity == "error"] == [], g


def test_a_malformed_grammar_raises_grammar_error_with_diagnostics():
    text = "piece brick {\n    vertex a (0, 0)\n    vertex a (1, 0)\n"
    with pytest.raises(clay.GrammarError) as caught:
        clay.Grammar.parse(text, path="broken.clay")
    err = caught.value
    assert isinstance(err, ValueError)
    assert err.diagnostics, "no diagnostics"
    first = err.diagnostics[0]
    assert first.path == "broken.clay"
    assert first.severity == "error" and first.code.startswith("E")
    assert first.line >= 1 and first.column >= 1
    # The message is the rendering clayc check prints.
    assert f"error[{first.code}]" in str(err)
    assert "broken.clay:" in str(err)


def test_the_rendered_message_points_into_the_file(root):
    fixture = root / "tests/fixtures/invalid/E011-unknown-piece.clay"
    with pytest.raises(clay.GrammarError) as caught:
        clay.Grammar.open(fixture)
    assert "18 │     wall = chain brik x 4" in str(caught.value)
    assert [d.code for d in caught.value.diagnostics] == ["E011"]


# --- errors are exceptions -----------------------------------------------------------------


def test_a_missing_grammar_is_file_not_found(tmp_path):
    missing = tmp_path / "nope.clay"
    with pytest.raises(FileNotFoundError) as caught:
        clay.Grammar.open(missing)
    assert caught.value.filename == str(missing)
    with pytest.raises(FileNotFoundError):
        clay.check(missing)
    with pytest.raises(IsADirectoryError):
        clay.Grammar.open(tmp_path)


def test_a_device_or_a_named_pipe_is_refused_before_it_is_read(tmp_path, grammars):
    # issue 47: Grammar.open('/dev/zero') grew to 23.9 GB before the kernel killed it
    with pytest.raises(OSError, match="not a regular file but a device"):
        clay.Grammar.open("/dev/zero")
    with pytest.raises(OSError, match="a device"):
        clay.check("/dev/zero")
    fifo = tmp_path / "pipe.clay"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match="named pipe"):
        clay.Grammar.open(fifo)
    s = clay.Session(clay.Grammar.open(grammars / "wall.clay"))
    with pytest.raises(OSError, match="named pipe"):
        s.run_script(fifo)


def test_a_path_must_be_a_path():
    with pytest.raises(TypeError, match="expected a path"):
        clay.Grammar.open(42)


def test_bad_scripts_are_value_errors_naming_the_step(grammars, tmp_path):
    s = clay.Session(clay.Grammar.open(grammars / "wall.clay"))
    bad = tmp_path / "bad.json"
    bad.write_text('{"steps": [\n  {"hold": {"frames": 1}},\n  {"jump": {}}\n]}')
    with pytest.raises(ValueError, match=r'bad\.json:3:3: step 1: unknown step "jump"'):
        s.run_script(bad)
    with pytest.raises(ValueError, match="step 0: drag needs"):
        s.run_script({"steps": [{"drag": {"frames": 3}}]})
    with pytest.raises(ValueError, match="not valid JSON"):
        bad.write_text("{")
        s.run_script(bad)
    with pytest.raises(FileNotFoundError):
        s.run_script(tmp_path / "missing.json")
    with pytest.raises(TypeError, match="run_script takes a path or a dict"):
        s.run_script(3.5)
    # Nothing ran.
    assert s.frames == 0


def test_non_finite_and_out_of_range_gestures_are_value_errors(grammars):
    s = clay.Session(clay.Grammar.open(grammars / "wall.clay"))
    s.grab(extreme="east")
    with pytest.raises(ValueError, match="drag: by must be a finite number, found nan"):
        s.drag(by=(float("nan"), 0), frames=3)
    with pytest.raises(ValueError, match="finite"):
        s.drag(to=(0, float("inf")))
    with pytest.raises(ValueError, match=r"outside \+/-1e9 m"):
        s.drag(by=(1e12, 0))
    with pytest.raises(ValueError, match='"frames" must be an integer from 0 to 100000, found -1'):
        s.hold(frames=-1)
    with pytest.raises(ValueError, match="found 2.5"):
        s.hold(frames=2.5)
    with pytest.raises(ValueError, match="too large"):
        s.hold(frames=2**80)
    with pytest.raises(ValueError, match=r'"extreme" must be "east"'):
        s.grab(extreme="up")
    with pytest.raises(TypeError, match="one of them"):
        s.grab(at=(0, 0), extreme="east")
    with pytest.raises(TypeError, match="one of them"):
        s.drag(frames=3)
    with pytest.raises(TypeError, match="pair of numbers"):
        s.cut(at=(1, 2, 3))
    with pytest.raises(ValueError, match="rotate: degrees must be a finite number"):
        s.rotate(float("nan"))
    with pytest.raises(TypeError, match="bool"):
        s.hold(frames=True)
    # None of them ran a frame, and the session still works.
    assert s.frames == 0
    s.drag(by=(0.5, 0), frames=2)
    assert s.frames == 2


def test_bad_solver_settings_are_value_errors(grammars):
    g = clay.Grammar.open(grammars / "wall.clay")
    with pytest.raises(ValueError, match=r"solver setting hysteresis=1.5: must be in \[0, 1\)"):
        clay.Session(g, hysteresis=1.5)
    with pytest.raises(ValueError, match="solver setting nrom: unknown parameter"):
        clay.Session(g, nrom=1)
    with pytest.raises(ValueError, match="expected cholesky or cg"):
        clay.Session(g, solver="lu")
    with pytest.raises(ValueError, match="finite"):
        clay.Session(g, norm=float("nan"))
    with pytest.raises(TypeError, match="bool"):
        clay.Session(g, norm=True)
    assert sorted(clay.SOLVER_SETTINGS) == sorted(
        [
            "hysteresis",
            "norm",
            "irls_epsilon",
            "merge_distance",
            "irls_iterations",
            "l2_iterations",
            "l2_anderson",
            "handle_weight",
            "solver",
        ]
    )


def test_notes_say_what_did_nothing(grammars):
    s = clay.Session(clay.Grammar.open(grammars / "wall.clay"))
    s.release()
    s.drag(by=(1, 0), frames=1)
    assert s.notes == [
        "step 0: release without a grabbed part",
        "step 1: drag without a grabbed part only holds",
    ]


# --- parameters ----------------------------------------------------------------------------

FENCE = """\
param bays = 4 in 2..12
param width = 1 in 0.5..2
let height = 0.5

site type joint

piece brick {
    vertex sw (0, 0)
    vertex se (width, 0)
    vertex ne (width, height)
    vertex nw (0, height)
    edges sw-se-ne-nw-sw
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
}

stretch brick from west to east

model {
    wall = chain brick x bays
}
"""


@pytest.fixture()
def fence(tmp_path):
    path = tmp_path / "fence.clay"
    path.write_text(FENCE)
    return path


def test_parameters_are_listed_with_their_values_defaults_and_ranges(fence):
    g = clay.Grammar.open(fence)
    assert [(p.name, p.value, p.default, p.range) for p in g.params] == [
        ("bays", 4.0, 4.0, (2.0, 12.0)),
        ("width", 1.0, 1.0, (0.5, 2.0)),
    ]
    assert g.instance_count == 4
    g = clay.Grammar.open(fence, params={"bays": 7, "width": 1.5})
    assert [(p.name, p.value, p.default) for p in g.params] == [
        ("bays", 7.0, 4.0),
        ("width", 1.5, 1.0),
    ]
    assert g.instance_count == 7
    s = clay.Session(g)
    assert s.summary()["pieces"] == {"brick": 7}
    assert s.summary()["bbox"][2] == pytest.approx(7 * 1.5)
    parsed = clay.Grammar.parse(FENCE, params={"bays": 3})
    assert parsed.instance_count == 3


def test_a_value_outside_the_range_names_the_parameter_and_its_range(fence):
    with pytest.raises(clay.GrammarError) as caught:
        clay.Grammar.open(fence, params={"bays": 20})
    [d] = caught.value.diagnostics
    assert d.code == "E071"
    assert (d.line, d.column) == (1, 7)
    assert "parameter `bays` is set to 20, outside its range 2..12" in d.message
    assert isinstance(caught.value, ValueError)
    with pytest.raises(clay.GrammarError, match="E071"):
        clay.Grammar.open(fence, params={"width": float("nan")})


def test_an_unknown_parameter_names_the_known_ones(fence):
    with pytest.raises(clay.GrammarError) as caught:
        clay.Grammar.open(fence, params={"bys": 3})
    [d] = caught.value.diagnostics
    assert d.code == "E070"
    assert "unknown parameter `bys`" in d.message
    assert "did you mean `bays`?" in d.hints
    assert "the parameters are `bays`, `width`" in d.hints
    with pytest.raises(clay.GrammarError, match="E070"):
        clay.Grammar.open(fence, params={"height": 1})


def test_parameter_arguments_are_checked(grammars, fence):
    assert clay.Grammar.open(grammars / "wall.clay").params == []
    with pytest.raises(clay.GrammarError, match="unknown parameter `bay`"):
        clay.Grammar.open(grammars / "wall.clay", params={"bay": 3})
    with pytest.raises(TypeError, match="params must be a dict"):
        clay.Grammar.open(fence, params=[("bays", 3)])
    with pytest.raises(TypeError, match="bays must be a number"):
        clay.Grammar.open(fence, params={"bays": "3"})
    with pytest.raises(TypeError, match="bool"):
        clay.Grammar.open(fence, params={"bays": True})


# --- the grammar ---------------------------------------------------------------------------


def test_pieces_and_counts(grammars):
    g = clay.Grammar.open(grammars / "castle.clay")
    names = [p.name for p in g.pieces]
    assert names[:2] == ["wall", "tower"]
    wall = g.pieces[0]
    assert wall.vertices == ["sw", "se", "ne", "nw"]
    assert wall.sites == ["west", "east"]
    assert g.instance_count == 35
    assert g.solver["hysteresis"] == 0.15
    assert g.path == str(grammars / "castle.clay")
    assert clay.Grammar.parse((grammars / "wall.clay").read_text()).path is None


# --- arrays and instances ------------------------------------------------------------------


def test_positions_are_a_float64_array_of_vertices_by_two(grammars):
    s = clay.Session(clay.Grammar.open(grammars / "castle.clay"))
    p = s.positions
    assert isinstance(p, np.ndarray)
    assert p.dtype == np.float64
    assert p.shape == (s.summary()["vertices"], 2)
    lo, hi = p.min(axis=0), p.max(axis=0)
    assert list(np.concatenate([lo, hi])) == pytest.approx(s.summary()["bbox"])
    # A copy: writing it changes nothing.
    p[:] = 0
    assert s.positions.max() > 0


def test_instances_know_their_piece_state_chain_and_vertices(grammars):
    s = clay.Session(clay.Grammar.open(grammars / "castle.clay"))
    inst = s.instances
    assert len(inst) == 35
    walls = [i for i in inst if i.piece == "wall"]
    towers = [i for i in inst if i.piece == "tower"]
    assert len(towers) == 4
    assert all(t.chain is None and t.index is None for t in towers)
    assert all(w.chain is not None for w in walls)
    chains = {w.chain for w in walls}
    assert len(chains) == 5
    for c in chains:
        assert sorted(w.index for w in walls if w.chain == c) == list(
            range(sum(1 for w in walls if w.chain == c))
        )
    p = s.positions
    for i in inst:
        assert len(i.vertices) == 4 or i.piece != "wall"
        assert i.centroid == pytest.approx(tuple(p[i.vertices].mean(axis=0)))
    assert len({i.id for i in inst}) == 35


# --- export and pictures -------------------------------------------------------------------


def test_exports_load(grammars, tmp_path):
    s = clay.Session(clay.Grammar.open(grammars / "castle.clay"))
    s.run_script(grammars / "castle.script.json")
    s.export(tmp_path / "castle.glb")
    s.export(tmp_path / "castle.gltf", thickness=0.2)
    s.export(tmp_path / "castle.obj")
    glb = (tmp_path / "castle.glb").read_bytes()
    magic, version, length = struct.unpack("<4sII", glb[:12])
    assert (magic, version, length) == (b"glTF", 2, len(glb))
    chunk_len, chunk_type = struct.unpack("<I4s", glb[12:20])
    doc = json.loads(glb[20 : 20 + chunk_len])
    assert chunk_type == b"JSON"
    # One root named after the grammar; its children the instances, in order, each naming
    # its instance in extras.
    [root] = doc["scenes"][0]["nodes"]
    assert doc["nodes"][root]["name"] == "castle"
    children = [doc["nodes"][k] for k in doc["nodes"][root]["children"]]
    assert [c["extras"]["instance"] for c in children] == [i.name for i in s.instances]
    gltf = json.loads((tmp_path / "castle.gltf").read_text())
    assert gltf["asset"]["version"] == "2.0"
    assert len(gltf["nodes"]) == len(s.instances) + 1
    assert (tmp_path / "castle.mtl").is_file()
    obj = (tmp_path / "castle.obj").read_text()
    assert "mtllib castle.mtl" in obj
    assert obj.count("\nv ") > 100
    try:
        import trimesh
    except ImportError:
        return
    loaded = trimesh.load(tmp_path / "castle.glb")
    assert len(loaded.geometry) > 0


def test_export_errors(grammars, tmp_path):
    s = clay.Session(clay.Grammar.open(grammars / "wall.clay"))
    with pytest.raises(ValueError, match="name it .glb, .gltf, .obj or .usda"):
        s.export(tmp_path / "wall.stl")
    with pytest.raises(FileNotFoundError):
        s.export(tmp_path / "no" / "such" / "dir" / "wall.glb")
    with pytest.raises(ValueError, match="thickness"):
        s.export(tmp_path / "wall.glb", thickness=-1)
    with pytest.raises(ValueError, match="at most 1000 metres"):
        s.export(tmp_path / "wall.glb", thickness=1e6)


def test_a_failed_obj_export_keeps_the_mtl_beside_it(grammars, tmp_path):
    # The .obj is written before its .mtl, as `clayc export` writes them: an .obj that cannot
    # be written (a folder of that name) leaves the user's .mtl as it was.
    s = clay.Session(clay.Grammar.open(grammars / "wall.clay"))
    (tmp_path / "wall.obj").mkdir()
    (tmp_path / "wall.mtl").write_text("# the user's materials\n")
    with pytest.raises(OSError):
        s.export(tmp_path / "wall.obj")
    assert (tmp_path / "wall.mtl").read_text() == "# the user's materials\n"


def test_the_scene_is_the_exports_nodes_and_meshes_with_z_up(grammars, tmp_path):
    s = clay.Session(clay.Grammar.open(grammars / "keep.clay"))
    nodes = s.scene()
    assert [n.instance for n in nodes] == [i.name for i in s.instances]
    s.export(tmp_path / "keep.gltf")
    doc = json.loads((tmp_path / "keep.gltf").read_text())
    # The glTF's root has one child per instance, in the instances' order: same name, the
    # translation at the pivot (y up: x, 0, -north) and the turn about y.
    [root] = doc["scenes"][0]["nodes"]
    children = [doc["nodes"][k] for k in doc["nodes"][root]["children"]]
    assert [c["name"] for c in children] == [n.name for n in nodes]
    for n, c in zip(nodes, children):
        x, y, z = c.get("translation", [0, 0, 0])
        assert (x, -z, y) == pytest.approx((*n.pivot, 0), abs=1e-9)
        q = c.get("rotation", [0, 0, 0, 1])
        assert 2 * math.atan2(q[1], q[3]) == pytest.approx(n.rotation, abs=1e-9)
        assert c["extras"]["piece"] == n.piece and c["extras"]["state"] == n.state
        assert c["extras"].get("chain") == n.chain and c["extras"].get("index") == n.index
        if n.mesh is not None:
            assert doc["meshes"][c["mesh"]]["name"] == n.mesh
    # A point of a primitive is placed by its node: the walls' bricks lie along their chains
    # in world space, and nodes of one mesh have the same primitives.
    by_mesh = {}
    for n in nodes:
        for p in n.primitives:
            by_mesh.setdefault((n.mesh, p.colour), []).append(p.positions)
    for arrays in by_mesh.values():
        assert all(np.array_equal(a, arrays[0]) for a in arrays)
    # A point of a primitive placed by its node is where the OBJ export (which writes world
    # coordinates, y up: x, height, -north) has it.
    s.export(tmp_path / "keep.obj")
    obj_vertices, current = {}, None
    for line in (tmp_path / "keep.obj").read_text().splitlines():
        if line.startswith("o "):
            current = obj_vertices.setdefault(line[2:].strip(), [])
        elif line.startswith("v "):
            current.append([float(v) for v in line.split()[1:4]])
    for n in nodes:
        c, sn = math.cos(n.rotation), math.sin(n.rotation)
        world = [
            np.column_stack([np.array(n.pivot) + local[:, :2] @ np.array([[c, sn], [-sn, c]]), local[:, 2]])
            for local in (p.positions.astype(np.float64) for p in n.primitives)
        ]
        world = np.concatenate(world) if world else np.zeros((0, 3))
        expected = np.array(obj_vertices.get(n.name, []), dtype=np.float64).reshape(-1, 3)
        expected = expected[:, [0, 2, 1]] * [1, -1, 1]
        assert world.shape == expected.shape, n.name
        assert world == pytest.approx(expected, abs=1e-4), n.name
    # The glTF's accessor bounds are y-up (x, height, -north); the scene's z-up; a shared mesh
    # is written once.
    tops = [doc["accessors"][p["attributes"]["POSITION"]]["max"][1] for m in doc["meshes"] for p in m["primitives"]]
    zs = [float(ps[0][:, 2].max()) for ps in by_mesh.values()]
    assert sorted(zs) == pytest.approx(sorted(tops), abs=1e-6)
    prim = next(p for n in nodes for p in n.primitives)
    assert prim.positions.dtype == np.float32 and prim.positions.shape[1] == 3
    assert prim.triangles.dtype == np.uint32 and prim.triangles.shape[1] == 3
    assert prim.triangles.max() < len(prim.positions)
    assert len(prim.colour) == 4 and all(0 <= c <= 255 for c in prim.colour)


def test_render_png_returns_png_bytes(grammars):
    s = clay.Session(clay.Grammar.open(grammars / "castle.clay"))
    s.run_script(grammars / "castle.script.json")
    png = s.render_png(size=(320, 200), overlays=["strain", "handles"])
    assert isinstance(png, bytes)
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", png[16:24])
    assert (width, height) == (320, 200)
    iso = s.render_png(size=(200, 150), view="iso")
    assert struct.unpack(">II", iso[16:24]) == (200, 150)
    with pytest.raises(ValueError, match="unknown overlay"):
        s.render_png(overlays=["nope"])
    with pytest.raises(ValueError, match="between 1 and"):
        s.render_png(size=(0, 10))
    with pytest.raises(ValueError, match="unknown view"):
        s.render_png(view="side")


def test_the_package_has_stubs_and_docstrings():
    import clay as package

    folder = Path(package.__file__).parent
    assert (folder / "py.typed").is_file()
    assert (folder / "_clay.pyi").is_file()
    for name in package.__all__:
        obj = getattr(package, name)
        if callable(obj):
            assert obj.__doc__, name
    for method in ["grab", "pin", "unpin", "drag", "rotate", "hold", "release", "cut", "frame",
                   "run_script", "summary", "export", "render_png", "scene"]:
        assert getattr(clay.Session, method).__doc__, method


# --- Python as Python users write it (issue 48, item 6) -------------------------------------


def test_points_are_any_pair_of_numbers_and_counts_numpy_integers(grammars):
    """A list, a numpy array or numpy scalars give the very session a tuple of floats gives."""
    g = clay.Grammar.open(grammars / "wall.clay")
    plain, numpyish = clay.Session(g), clay.Session(g)
    plain.pin(at=(0.25, 0.25))
    plain.grab(at=(7.5, 0.25))
    plain.drag(to=(10.0, 1.0), frames=3)
    plain.drag(by=(1.0, 0.0), frames=2)
    plain.cut(at=(3.0, 0.25))
    numpyish.pin(at=np.array([0.25, 0.25]))
    numpyish.grab(at=[7.5, 0.25])
    numpyish.drag(to=[np.float32(10), np.int64(1)], frames=np.int64(3))
    numpyish.drag(by=np.array([1, 0]), frames=np.uint8(2))
    numpyish.cut(at=(x for x in (3.0, 0.25)))
    assert numpyish.frames == plain.frames == 5
    assert np.array_equal(numpyish.positions, plain.positions)
    assert without_times(numpyish.summary()) == without_times(plain.summary())
    # Solver settings and parameters take numpy numbers too.
    assert clay.Session(g, l2_iterations=np.int64(40), norm=np.float64(0.5)) is not None


def test_what_is_not_a_point_or_a_count_is_a_type_error(grammars):
    s = clay.Session(clay.Grammar.open(grammars / "wall.clay"))
    for bad in ["xy", b"xy", {1: 2, 3: 4}, [1], [1, 2, 3], np.zeros(3), np.zeros((2, 2)), 5, None,
                [True, 0], ["1", 2]]:
        with pytest.raises(TypeError, match="must be a pair of numbers"):
            s.cut(at=bad)
    with pytest.raises(TypeError, match="bool"):
        s.hold(frames=np.bool_(True))
    with pytest.raises(ValueError, match="too large"):
        s.hold(frames=np.uint64(2**63))
    with pytest.raises(ValueError, match="finite"):
        s.cut(at=np.array([np.nan, 0.0]))
    assert s.frames == 0


def test_exceptions_and_classes_live_in_clay_and_read_well(grammars, fence):
    for name in ["GrammarError", "SolverError", "InternalError"]:
        assert getattr(clay, name).__module__ == "clay", name
    with pytest.raises(clay.GrammarError) as caught:
        clay.Grammar.parse("piece {")
    assert type(caught.value).__module__ == "clay"
    g = clay.Grammar.open(grammars / "wall.clay")
    s = clay.Session(g)
    s.pin(extreme="west")
    s.grab(extreme="east")
    s.drag(by=(8.0, 0.0), frames=100)
    prim = next(n for n in s.scene() if n.primitives).primitives[0]
    shown = [g, g.pieces[0], s, s.instances[0], s.rule_log[0], s.scene()[0], prim,
             caught.value.diagnostics[0], clay.Grammar.open(fence).params[0]]
    for obj in shown:
        text = repr(obj)
        assert text.startswith(type(obj).__name__ + "("), text
        assert " object at 0x" not in text, text
    assert repr(prim) == (
        f"Primitive(#{''.join(f'{c:02x}' for c in prim.colour)}, "
        f"{len(prim.positions)} vertices, {len(prim.triangles)} triangles)"
    )


def test_the_distribution_is_clay_sculpt_and_imports_as_clay():
    """`clay` on the package index is another project; ours installs as clay-sculpt."""
    from importlib import metadata

    assert metadata.version("clay-sculpt") == clay.__version__
    top = (metadata.distribution("clay-sculpt").read_text("top_level.txt") or "clay").split()
    assert top == ["clay"]


# --- USD (issue 48, item 4) -------------------------------------------------------------------


@pytest.mark.parametrize("name", ["castle", "keep"])
def test_the_usd_export_opens_validates_and_places_every_point_as_the_scene(grammars, tmp_path, name):
    """usd-core opens the .usda, every validator of its registry passes, metres and Z up are
    declared, one Xform per instance under one root carries the instance's names, the meshes are
    shared by instancing, and every point lands where the scene (the glTF's nodes) has it."""
    from pxr import Gf, Usd, UsdGeom, UsdShade, UsdValidation

    s = clay.Session(clay.Grammar.open(grammars / f"{name}.clay"))
    script = grammars / f"{name}.script.json"
    if script.is_file():
        s.run_script(script)
    path = tmp_path / f"{name}.usda"
    s.export(path)
    stage = Usd.Stage.Open(str(path))
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    assert UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    root = stage.GetDefaultPrim()
    assert root.GetName() == name and root.IsA(UsdGeom.Xform)
    registry = UsdValidation.ValidationRegistry()
    errors = UsdValidation.ValidationContext(registry.GetOrLoadAllValidators()).Validate(stage)
    assert [(e.GetName(), e.GetMessage()) for e in errors] == []

    nodes = s.scene()
    xforms = [p for p in root.GetChildren() if p.HasAttribute("userProperties:instance")]
    assert [p.GetName() for p in xforms] == [n.name for n in nodes]
    cache = UsdGeom.XformCache()
    colours = {}
    for prim, n in zip(xforms, nodes):
        get = lambda a: prim.GetAttribute(f"userProperties:{a}").Get()
        assert (get("instance"), get("piece"), get("state"), get("id")) == (
            n.instance, n.piece, n.state, n.id)
        assert get("chain") == n.chain and get("index") == n.index
        meshes = [m for m in Usd.PrimRange(prim, Usd.TraverseInstanceProxies()) if m.IsA(UsdGeom.Mesh)]
        assert len(meshes) == len(n.primitives), n.name
        c, sn = math.cos(n.rotation), math.sin(n.rotation)
        for mesh, p in zip(meshes, n.primitives):
            m = cache.GetLocalToWorldTransform(mesh)
            world = np.array([list(m.Transform(Gf.Vec3d(*map(float, q)))) for q in UsdGeom.Mesh(mesh).GetPointsAttr().Get()])
            local = p.positions.astype(np.float64)
            expected = np.column_stack([np.array(n.pivot) + local[:, :2] @ np.array([[c, sn], [-sn, c]]), local[:, 2]])
            assert world == pytest.approx(expected, abs=1e-4), n.name
            indices = np.array(UsdGeom.Mesh(mesh).GetFaceVertexIndicesAttr().Get()).reshape(-1, 3)
            assert np.array_equal(indices, p.triangles), n.name
            st = np.array(UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st").Get())
            assert p.uvs.dtype == np.float32 and p.uvs.shape == (len(p.positions), 2)
            assert np.array_equal(st, p.uvs), n.name
            material, _ = UsdShade.MaterialBindingAPI(mesh).ComputeBoundMaterial()
            shader = UsdShade.Shader(material.GetSurfaceOutput().GetConnectedSources()[0][0].source.GetPrim())
            assert shader.GetIdAttr().Get() == "UsdPreviewSurface"
            assert material.GetPrim().GetName() == p.material
            colours[material.GetPath()] = p.colour, shader.GetInput("diffuseColor").Get()
    # Meshes shared: one prototype per distinct mesh of the scene.
    assert len(stage.GetPrototypes()) == len({n.mesh for n in nodes if n.mesh is not None})
    # Colours linear, as glTF's factor.
    linear = lambda b: (b / 255 / 12.92) if b / 255 <= 0.04045 else ((b / 255 + 0.055) / 1.055) ** 2.4
    for srgb, diffuse in colours.values():
        assert list(diffuse) == pytest.approx([linear(b) for b in srgb[:3]], abs=1e-5)


def test_a_script_recorded_with_other_parameters_raises_script_params_error(fence, tmp_path):
    """Issue 48, item 3: a script says the parameters it was recorded with; on other values
    its gestures would grab other parts, so it is refused (before any step runs) naming them."""
    script = {
        "params": {"bays": 6},
        "steps": [{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}},
                  {"drag": {"by": [2, 0], "frames": 10}}],
    }
    s = clay.Session(clay.Grammar.open(fence))
    with pytest.raises(clay.ScriptParamsError, match=r"bays = 6 \(the grammar has 4\)") as caught:
        s.run_script(script)
    assert isinstance(caught.value, ValueError)
    assert s.frames == 0
    path = tmp_path / "pull.script.json"
    path.write_text(json.dumps(script))
    with pytest.raises(clay.ScriptParamsError, match="pull.script.json"):
        s.run_script(path)
    ok = clay.Session(clay.Grammar.open(fence, params={"bays": 6}))
    ok.run_script(path)
    assert ok.frames == 10


def test_typed_parameters_take_and_give_python_types(grammars):
    keep = grammars / "keep.clay"
    g = clay.Grammar.open(keep)
    by_name = {p.name: p for p in g.params}
    assert by_name["wall_height"].kind == "number"
    assert by_name["donjon"].kind == "bool" and by_name["donjon"].value is True
    gate = by_name["gate"]
    assert (gate.kind, gate.value, gate.choices) == ("choice", "great_gate", ["great_gate", "gatehouse"])
    assert repr(gate) == "Param(gate: choice = great_gate, default great_gate)"
    # A bool switches the donjon off; a choice picks the plainer gate.
    plain = clay.Grammar.open(keep, params={"donjon": False, "gate": "gatehouse"})
    s = clay.Session(plain)
    pieces = {i.piece for i in s.instances}
    assert "donjon" not in pieces and "gatehouse" in pieces and "great_gate" not in pieces
    values = {p.name: p.value for p in plain.params}
    assert values["donjon"] is False and values["gate"] == "gatehouse"
    # numpy's bool is a bool.
    assert clay.Grammar.open(keep, params={"donjon": np.bool_(False)}).params[2].value is False
    # Another type is a TypeError naming what the parameter takes.
    with pytest.raises(TypeError, match="params: donjon must be a bool, found int"):
        clay.Grammar.open(keep, params={"donjon": 1})
    with pytest.raises(TypeError, match="params: gate must be a str, one of 'great_gate', 'gatehouse', found int"):
        clay.Grammar.open(keep, params={"gate": 2})
    # A choice the grammar does not list is the grammar's error, with the closest one.
    with pytest.raises(clay.GrammarError) as caught:
        clay.Grammar.open(keep, params={"gate": "gatehose"})
    [d] = caught.value.diagnostics
    assert d.code == "E073"
    assert 'did you mean "gatehouse"?' in d.hints


def test_an_int_parameter_refuses_a_fraction(tmp_path):
    text = (
        "param bays: int = 3 in 2..9\nsite type j\n"
        "piece b { vertex a (0, 0) vertex c (1, 0) vertex d (1, 1) vertex e (0, 1)\n"
        "  edges a-c-d-e-a, a-d site west: j [e, a] out (-1, 0) site east: j [c, d] out (1, 0) }\n"
        "stretch b from west to east\nmodel { w = chain b x bays }\n"
    )
    g = clay.Grammar.parse(text, params={"bays": np.int64(5)})
    assert g.params[0].value == 5 and isinstance(g.params[0].value, int)
    assert clay.Grammar.parse(text, params={"bays": 6.0}).params[0].value == 6
    with pytest.raises(TypeError, match=r"params: bays must be a whole number \(an int parameter\), found 2.5"):
        clay.Grammar.parse(text, params={"bays": 2.5})


def test_a_usdc_export_is_the_usda_in_usds_binary_form(grammars, tmp_path):
    """Issue 48, item 4: `.usdc` (which no Rust crate writes) through usd-core's pxr: the
    file is USD's crate form and holds the stage the .usda export holds."""
    from pxr import Usd

    s = clay.Session(clay.Grammar.open(grammars / "castle.clay"))
    s.export(tmp_path / "castle.usdc")
    s.export(tmp_path / "castle.usda")
    assert (tmp_path / "castle.usdc").read_bytes()[:8] == b"PXR-USDC"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["castle.usda", "castle.usdc"]
    binary, text = (Usd.Stage.Open(str(tmp_path / f"castle.{e}")) for e in ("usdc", "usda"))
    paths = lambda stage: [str(p.GetPath()) for p in stage.Traverse()]
    assert paths(binary) == paths(text) and len(paths(text)) > 40
    assert binary.GetDefaultPrim().GetName() == "castle"
