"""The Python package against the command line and against physics: run by tests/it/python.rs with the
package installed (`pip install .`) into a virtual environment the tests make. DRAPELAB_BIN is the
command line built by the same `cargo test`; the working folder is the repository root."""

import json
import math
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pyarrow.parquet as pq
import pytest

try:
    import tomllib
except ImportError:  # Python < 3.11
    tomllib = None

import drapelab

ROOT = pathlib.Path(__file__).resolve().parents[2]
HANG4 = ROOT / "datasets/scenes/hang4.toml"
BIN = os.environ["DRAPELAB_BIN"]


def cli_simulate(tmp_path, scene, *sets):
    out = tmp_path / "cli"
    args = [BIN, "simulate", str(scene), "--out", str(out)]
    for s in sets:
        args += ["--set", s]
    subprocess.run(args, check=True, capture_output=True)
    return out


def test_simulate_equals_the_command_line_to_1e_12_m(tmp_path):
    r = drapelab.simulate(HANG4, set={"cloth.nx": 21, "cloth.ny": 21})
    assert r.status == "converged" and r.converged
    assert r.positions.shape == (441, 3) and r.positions.dtype == np.float64
    assert r.present.all() and r.triangles.shape == (2 * 20 * 20, 3)
    t = pq.read_table(cli_simulate(tmp_path, HANG4, "cloth.nx=21", "cloth.ny=21") / "particles.parquet")
    cli = np.column_stack([t["x_m"].to_numpy(), t["y_m"].to_numpy(), t["z_m"].to_numpy()])
    order = t["j"].to_numpy() * 21 + t["i"].to_numpy()
    assert np.abs(r.positions[order] - cli).max() <= 1e-12
    # Force balance, independently of the solver: the four corners carry the sheet's weight.
    assert r.report["max_residual_N"] < 1e-6 * 0.045 * 0.25 * 9.80665
    assert r.report["iterations"] > 0 and r.report["energy_J"] < 0


def test_sensitivity_equals_the_command_lines_table_and_a_central_difference(tmp_path):
    key = "material.mass_spring.stiffness_N_per_m"
    r = drapelab.simulate(HANG4, sensitivity=[key])
    s = r.sensitivity(key)
    assert s.shape == r.positions.shape
    out = tmp_path / "cli"
    subprocess.run([BIN, "simulate", str(HANG4), "--out", str(out), "--sensitivity", key],
                   check=True, capture_output=True)
    t = pq.read_table(out / "sensitivity.parquet")
    assert set(t["key"].to_pylist()) == {key}
    cli = np.column_stack([t[c].to_numpy() for c in ("dx_m_per_unit", "dy_m_per_unit", "dz_m_per_unit")])
    order = t["j"].to_numpy() * r.nx + t["i"].to_numpy()
    assert np.abs(s[order] - cli).max() <= 1e-15
    # Against the drapes at k (1 ± 1e-4): a stiffer net sags less, by the amount the factor says.
    k = 1000.0
    hi = drapelab.simulate(HANG4, set={key: k * (1 + 1e-4)}).positions
    lo = drapelab.simulate(HANG4, set={key: k * (1 - 1e-4)}).positions
    fd = (hi - lo) / (2e-4 * k)
    assert np.linalg.norm(s - fd) <= 1e-4 * np.linalg.norm(fd)
    centre = (r.ny // 2) * r.nx + r.nx // 2
    assert s[centre, 2] > 0
    dj = np.zeros_like(s)
    dj[centre, 2] = 1.0
    assert r.gradient(dj, [key])[key] == pytest.approx(s[centre, 2])
    with pytest.raises(KeyError):
        r.sensitivity("gravity.g_m_per_s2")
    with pytest.raises(drapelab.InputError, match="cloth.nx"):
        drapelab.simulate(HANG4, sensitivity=["cloth.nx"])


def test_a_drape_free_to_turn_lists_its_neutral_mode():
    r = drapelab.simulate(ROOT / "datasets/scenes/sphere_wool.toml", set={"cloth.nx": 21, "cloth.ny": 21})
    assert r.converged
    (mode,) = r.neutral_modes
    assert mode["kind"] == "turn" and mode["axis"] == [0.0, 0.0, 1.0]
    assert drapelab.simulate(HANG4).neutral_modes == []


def test_a_scene_draped_in_a_fabric_file_equals_its_material_inline():
    sphere = ROOT / "datasets/scenes/sphere_wool.toml"
    wool = ROOT / "datasets/fabrics/wool_seed003.toml"
    inline = drapelab.simulate(sphere, set={"cloth.nx": 21, "cloth.ny": 21})
    in_fabric = drapelab.simulate(sphere, set={"cloth.nx": 21, "cloth.ny": 21}, fabric=wool)
    assert inline.converged and np.array_equal(inline.positions, in_fabric.positions)
    with pytest.raises(drapelab.InputError, match="fabric"):
        drapelab.simulate(sphere, fabric=ROOT / "datasets/fabrics/nowhere.toml")


def test_a_drape_with_friction_refuses_sensitivities_naming_friction():
    rod = HANG4.parent / "rod_polyester.toml"
    key = "contact.friction_coefficient"
    with pytest.raises(drapelab.InputError, match=r"contact\.friction_coefficient.*friction"):
        drapelab.simulate(rod, set={key: 0.3}, sensitivity=[key])


def test_the_table_carries_its_run_metadata_in_the_arrow_schema(tmp_path):
    r = drapelab.simulate(HANG4)
    saved = r.save(tmp_path / "run")
    meta = pq.read_table(saved / "particles.parquet").schema.metadata
    assert meta[b"status"] == b"converged"
    assert meta[b"scene"] == b"hang4"
    assert meta[b"drapelab_version"] == drapelab.__version__.encode()
    assert meta[b"solver"].decode() == r.report["solver"]
    assert sorted(p.name for p in saved.iterdir()) == ["iterations.parquet", "particles.parquet", "run.json", "triangles.parquet"]
    assert json.loads((saved / "run.json").read_text())["status"] == "converged"
    df = r.to_polars()
    assert df.columns == ["i", "j", "x_m", "y_m", "z_m", "present"]
    assert np.allclose(df["z_m"].to_numpy(), r.positions[df["j"].to_numpy() * r.nx + df["i"].to_numpy(), 2], atol=0)


@pytest.mark.skipif(tomllib is None, reason="tomllib needs Python 3.11")
def test_a_dict_scene_equals_its_toml():
    with open(HANG4, "rb") as f:
        table = tomllib.load(f)
    assert drapelab.read_scene(HANG4) == table
    a = drapelab.simulate(table, set={"cloth.nx": 15, "cloth.ny": 15})
    b = drapelab.simulate(HANG4, set={"cloth.nx": 15, "cloth.ny": 15})
    assert a.status == b.status == "converged"
    assert np.array_equal(a.positions, b.positions)
    table["material"]["mass_spring"]["stiffness_N_per_m"] = 500.0
    softer = drapelab.simulate(table, set={"cloth.nx": 15, "cloth.ny": 15})
    # Softer springs sag further: the centre hangs lower.
    c = 7 * 15 + 7
    assert softer.positions[c, 2] < a.positions[c, 2]


def test_input_errors_name_the_key():
    with pytest.raises(drapelab.InputError, match=r"cloth\.nxx") as e:
        drapelab.simulate(HANG4, set={"cloth.nxx": 5})
    assert isinstance(e.value, ValueError)
    with pytest.raises(drapelab.InputError, match=r"set\[\"cloth\.nx\"\].*cloth\.nx"):
        drapelab.simulate(HANG4, set={"cloth.nx": -3})
    with pytest.raises(drapelab.InputError, match=r"hang4\.toml.*solver\.static\.max_iterations"):
        drapelab.simulate(HANG4, set={"solver.static.max_iterations": "many"})
    table = drapelab.read_scene(HANG4)
    table["cloth"]["size_x_mm"] = 500
    with pytest.raises(drapelab.InputError, match=r"scene \(dict\).*size_x_mm"):
        drapelab.simulate(table)
    with pytest.raises(drapelab.InputError, match=r"no_such\.toml"):
        drapelab.simulate("no_such.toml")


def test_a_solve_that_does_not_converge_is_a_status_not_an_exception():
    r = drapelab.simulate(HANG4, set={"cloth.nx": 21, "cloth.ny": 21, "solver.static.max_iterations": 2})
    assert r.status == "max-iterations" and not r.converged
    assert r.report["iterations"] == 2
    assert r.table_path().name == "last_state.parquet"
    assert np.isfinite(r.positions).all()


def test_ctrl_c_stops_a_long_solve_within_a_second(tmp_path):
    script = textwrap.dedent(f"""
        import sys, drapelab
        print("solving", flush=True)
        try:
            drapelab.simulate({str(HANG4)!r}, set={{
                "cloth.nx": 31, "cloth.ny": 31, "solver.kind": "symplectic-euler",
                "solver.dynamic.dt_s": 1e-5, "solver.dynamic.max_time_s": 1e4,
                "solver.dynamic.speed_tol_m_per_s": 1e-30, "solver.dynamic.residual_tol_rel": 1e-30}})
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(3)
        print("finished", flush=True)
    """)
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "solving"
    time.sleep(2.0)
    assert p.poll() is None, "the solve must still be running"
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=30)
    waited = time.monotonic() - sent
    assert p.returncode == 3, (out, err)
    assert "interrupted" in out
    assert waited < 1.0, f"stopped {waited:.2f} s after SIGINT"


def disc(radius_m, rings=40, sectors=180):
    """A flat disc mesh at z = 0, centred on the axis."""
    pts = [(0.0, 0.0, 0.0)]
    tris = []
    for k in range(1, rings + 1):
        r = radius_m * k / rings
        pts += [(r * math.cos(2 * math.pi * s / sectors), r * math.sin(2 * math.pi * s / sectors), 0.0) for s in range(sectors)]
    for s in range(sectors):
        tris.append((0, 1 + s, 1 + (s + 1) % sectors))
    for k in range(1, rings):
        a, b = 1 + (k - 1) * sectors, 1 + k * sectors
        for s in range(sectors):
            s1 = (s + 1) % sectors
            tris += [(a + s, b + s, b + s1), (a + s, b + s1, a + s1)]
    return np.array(pts), np.array(tris)


def test_drape_coefficient_of_flat_discs_is_exact():
    # BS 5058: DC = (S - A_pedestal) / (A_specimen - A_pedestal); the tester's 9 cm pedestal, 15 cm specimen.
    flat = drapelab.measure_drape(*disc(0.15))
    assert flat["drape_coefficient_pct"] == pytest.approx(100.0, abs=0.5)
    half = drapelab.measure_drape(*disc(0.12))
    assert half["drape_coefficient_pct"] == pytest.approx(100 * (0.12**2 - 0.09**2) / (0.15**2 - 0.09**2), abs=0.5)
    assert half["nodes"] == 0
    assert np.allclose(half["outline_radius_m"], 0.12, atol=2e-3)


def test_a_cusick_silhouette_and_its_registered_mesh_agree():
    photo = ROOT / "datasets/cusick/fabric_01/silhouettes/sample_01_capture_1.jpg"
    m = drapelab.measure_silhouette(photo)
    assert 20 < m["drape_coefficient_pct"] < 95
    assert 3 <= m["nodes"] <= 12
    assert m["outline_radius_m"].shape == (360,)
    with pytest.raises(drapelab.InputError, match="no_such.png"):
        drapelab.measure_silhouette("no_such.png")


def test_fit_edges_equals_the_command_line(tmp_path):
    photo = ROOT / "datasets/knitted/sample_01/hang4/photo.png"
    edges = drapelab.fit_edges(photo)
    out = tmp_path / "fit"
    subprocess.run([BIN, "fit-edges", str(photo), "--out", str(out), "--camera-json", str(photo.parent / "camera.json")],
                   check=True, capture_output=True)
    rows = pq.read_table(out / "edges.parquet").to_pylist()
    assert sorted(e["edge"] for e in edges) == sorted({r["edge"] for r in rows}) and edges
    for e in edges:
        mine = [r for r in rows if r["edge"] == e["edge"]]
        assert [r["coefficient_cm"] for r in sorted(mine, key=lambda r: r["power"])] == e["coefficients"]
        assert len(e["coefficients"]) == 5
        # A rendered photo of a simulated hang: the polynomial follows the edge to a fraction of a pixel.
        assert e["rms_residual_cm"] < 0.1 and e["n_points"] > 100
    with pytest.raises(drapelab.InputError, match="camera.json"):
        drapelab.fit_edges(photo, camera=tmp_path / "camera.json")


@pytest.fixture(scope="module")
def project(tmp_path_factory):
    """A small project (one knitted sample's 4-corner photo, the samples table, hang4) whose pipeline
    fits the photo's edges and solves hang4, run once through `drapelab.run_pipeline`."""
    root = tmp_path_factory.mktemp("project")
    for rel in ["datasets/knitted/sample_03/hang4/photo.png", "datasets/knitted/sample_03/hang4/camera.json",
                "datasets/knitted/knitted_samples.csv", "datasets/scenes/hang4.toml"]:
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_bytes((ROOT / rel).read_bytes())
    (root / "pipelines").mkdir()
    (root / "pipelines/p.toml").write_text(textwrap.dedent("""
        name = "p"
        [stages.fit4]
        kind = "fit-edges"
        inputs.photos = ["datasets/knitted/*/hang4/photo.png"]
        inputs.cameras = ["datasets/knitted/*/hang4/camera.json"]
        outputs.edges = "{run}/fit4/edges.parquet"
        [stages.sim]
        kind = "simulate"
        inputs.scene = "datasets/scenes/hang4.toml"
        outputs.run = "{run}/sim/run.json"
        outputs.particles = "{run}/sim/particles.parquet"
        params.set = { "cloth.nx" = 13, "cloth.ny" = 13 }
    """))
    cwd = os.getcwd()
    os.chdir(root)
    try:
        first = drapelab.run_pipeline("pipelines/p.toml")
    finally:
        os.chdir(cwd)
    return root, first


def test_run_pipeline_is_make_style(project, monkeypatch):
    root, first = project
    assert first["ok"] and sorted(first["ran"]) == ["fit4", "sim"], first
    monkeypatch.chdir(root)
    again = drapelab.run_pipeline("pipelines/p.toml")
    assert again["ran"] == [] and sorted(again["up_to_date"]) == ["fit4", "sim"], again
    events = []
    forced = drapelab.run_pipeline("pipelines/p.toml", force=["sim"],
                                   progress=lambda *e: events.append(e))
    assert forced["ran"] == ["sim"] and forced["up_to_date"] == ["fit4"]
    # The callback saw the skip, the forced stage start and finish.
    assert ("fit4", "skipped", 0, 0) in events, events
    kinds = [e[1] for e in events if e[0] == "sim"]
    assert kinds[0] == "started" and kinds[-1] == "finished", events

    def fail(*_):
        raise RuntimeError("from the callback")

    with pytest.raises(RuntimeError, match="from the callback"):
        drapelab.run_pipeline("pipelines/p.toml", force=["sim"], progress=fail)
    assert (root / "runs/p/sim/particles.parquet").exists()
    with pytest.raises(drapelab.InputError, match="nope.toml"):
        drapelab.run_pipeline("pipelines/nope.toml")


ICA = {"decades": 4, "countries": 12, "imperialists": 3, "beta": 2.0, "gamma": 0.5,
       "revolution_rate": 0.1, "xi": 0.1, "seed": 1}


def test_calibrate_one_sample_returns_its_row(project, monkeypatch):
    root, _ = project
    monkeypatch.chdir(root)
    edges = "runs/p/fit4/edges.parquet"
    kw = dict(samples="datasets/knitted/knitted_samples.csv", scene="datasets/scenes/hang4.toml", ica=ICA)
    row = drapelab.calibrate(edges, "datasets/knitted/sample_03/hang4", runs=1, grid=8, polish_iterations=0, **kw)
    assert row["sample"] == "datasets/knitted/sample_03/hang4"
    assert row["runs"] == 1 and row["simulations"] > 0
    # Seed 000 Table 3's box: 500 to 1200 N/m.
    assert 500 <= row["stiffness_N_per_m"] <= 1200 and math.isfinite(row["curve_distance_pct"])
    with pytest.raises(drapelab.InputError, match="runs"):
        drapelab.calibrate(edges, "datasets/knitted/sample_03/hang4", runs=0, **kw)
    with pytest.raises(RuntimeError, match="no edges of sample"):
        drapelab.calibrate(edges, "datasets/knitted/sample_99/hang4", runs=1, **kw)


def test_calibrate_by_gradients_recovers_the_natural_length(project, monkeypatch):
    # Sample 3 was made with a natural length of 53 mm (datasets/knitted/ground_truth.csv):
    # Levenberg–Marquardt on the drapes' sensitivities finds it in a few dozen solves, no ICA needed.
    root, _ = project
    monkeypatch.chdir(root)
    edges = "runs/p/fit4/edges.parquet"
    kw = dict(samples="datasets/knitted/knitted_samples.csv", scene="datasets/scenes/hang4.toml")
    row = drapelab.calibrate(edges, "datasets/knitted/sample_03/hang4", optimizer="levenberg-marquardt", **kw)
    assert row["optimizer"] == "levenberg-marquardt" and row["topology"] in ("a", "b", "c")
    assert abs(row["natural_length_m"] - 0.053) < 0.01 * 0.053, row
    assert 500 <= row["stiffness_N_per_m"] <= 1200 and row["curve_distance_pct"] < 0.1, row
    assert 1 <= row["solves"] <= 75, row
    with pytest.raises(drapelab.InputError, match="optimizer"):
        drapelab.calibrate(edges, "datasets/knitted/sample_03/hang4", optimizer="newton", **kw)
    with pytest.raises(drapelab.InputError, match="ica"):
        drapelab.calibrate(edges, "datasets/knitted/sample_03/hang4", **kw)


@pytest.mark.parametrize("script, picture, says", [
    ("sag_sweep.py", "sag_vs_stiffness.png", "drape coefficient"),
    ("drape_3d.py", "drape_3d.png", "wrote"),
])
def test_the_examples_run(tmp_path, script, picture, says):
    env = dict(os.environ, MPLBACKEND="Agg", DRAPELAB_EXAMPLE_OUT=str(tmp_path))
    out = subprocess.run([sys.executable, str(ROOT / "examples/python" / script)], cwd=ROOT, env=env,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / picture).stat().st_size > 1000
    assert says in out.stdout


def test_frames_grid_view_and_pandas(tmp_path):
    r = drapelab.simulate(HANG4, overrides={"cloth.nx": 15, "cloth.ny": 15}, frames=4)
    assert r.converged
    g = r.grid()
    assert g.shape == (15, 15, 3)
    # grid()[j, i] is row j, column i: the particle at grid order j * nx + i.
    assert np.array_equal(g[3, 5], r.positions[3 * 15 + 5])
    x, index, t = r.frames()
    assert t is None  # a static solve has no simulated time
    assert 2 <= len(index) <= 4 and index[0] == 0 and np.all(np.diff(index) > 0)
    assert x.shape == (len(index), 225, 3)
    # The first frame is the start, not the drape; frames are states of this solve.
    assert np.abs(x[0] - r.positions).max() > 1e-3
    dynamic = drapelab.simulate(HANG4, overrides={
        "cloth.nx": 9, "cloth.ny": 9, "solver.kind": "implicit-euler", "solver.dynamic.max_time_s": 0.5},
        frames=10)
    xd, idx, td = dynamic.frames()
    assert td is not None and np.all(np.diff(td) > 0) and len(idx) <= 10
    with pytest.raises(RuntimeError, match="frames"):
        drapelab.simulate(HANG4, overrides={"cloth.nx": 9, "cloth.ny": 9}).frames()
    pd = pytest.importorskip("pandas")
    df = r.to_pandas()
    assert list(df.columns) == ["i", "j", "x_m", "y_m", "z_m", "present"]
    table = pq.read_table(r.table_path()).to_pandas()
    assert np.array_equal(df["z_m"].to_numpy(), table["z_m"].to_numpy())
    assert np.array_equal(df["i"].to_numpy(), table["i"].to_numpy())


def test_the_progress_callback_sees_the_solve_and_can_stop_it():
    calls = []
    slow = {"cloth.nx": 41, "cloth.ny": 41, "solver.kind": "implicit-euler",
            "solver.dynamic.max_time_s": 2.0}
    r = drapelab.simulate(HANG4, overrides=slow, progress=lambda *a: calls.append(a))
    assert calls, "no progress call"
    i, t, res, e = calls[-1]
    assert isinstance(i, int) and t is not None and res >= 0 and math.isfinite(e)

    class Enough(Exception):
        pass

    def stop(*_):
        raise Enough("seen enough")

    with pytest.raises(Enough):
        drapelab.simulate(HANG4, overrides=slow, progress=stop)


def test_simulate_many_equals_one_by_one_and_runs_in_parallel():
    import threading
    over = [{"cloth.nx": 41, "cloth.ny": 41, "material.mass_spring.stiffness_N_per_m": k}
            for k in (300.0, 600.0, 900.0, 1200.0)]
    t0 = time.perf_counter()
    one = [drapelab.simulate(HANG4, overrides=o) for o in over]
    serial = time.perf_counter() - t0
    t0 = time.perf_counter()
    many = drapelab.simulate_many(HANG4, overrides=over, threads=2)
    parallel = time.perf_counter() - t0
    for a, b in zip(one, many):
        assert a.status == b.status == "converged"
        assert np.array_equal(a.positions, b.positions)
    print(f"4 solves: one by one {serial:.2f} s, on 2 threads {parallel:.2f} s")
    # Two solves on two threads are in flight at once (the solves release the GIL): their
    # progress calls interleave, A B A, where one after the other would give A… B… (times are
    # printed above, not asserted).
    calls = []
    drapelab.simulate_many(HANG4, overrides=over[:2], threads=2,
                           progress=lambda *a: calls.append(threading.get_ident()))
    assert len(set(calls)) == 2, calls
    assert sum(a != b for a, b in zip(calls, calls[1:])) >= 2, calls
    # Several scenes, paired with their overrides; a bad count is an input error.
    two = drapelab.simulate_many([HANG4, ROOT / "datasets/scenes/hang2.toml"],
                                 overrides=[{"cloth.nx": 9, "cloth.ny": 9}] * 2)
    assert [r.scene["name"] for r in two] == ["hang4", "hang2"]
    with pytest.raises(drapelab.InputError, match="overrides"):
        drapelab.simulate_many([HANG4, HANG4], overrides=[{}] * 3)


def test_set_is_the_old_name_of_overrides():
    a = drapelab.simulate(HANG4, set={"cloth.nx": 9, "cloth.ny": 9})
    b = drapelab.simulate(HANG4, overrides={"cloth.nx": 9, "cloth.ny": 9})
    assert np.array_equal(a.positions, b.positions)
    with pytest.raises(drapelab.InputError, match="set"):
        drapelab.simulate(HANG4, overrides={}, set={})


def test_a_mesh_scene_simulates_with_the_files_vertices_and_triangles():
    # Issue 49: the Cusick specimen read from OBJ; positions in the file's vertex order, its
    # triangles, and the tester's measures of the result agree with the run's own.
    scene = ROOT / "datasets/patterns/cusick_disc_pedestal.toml"
    obj = (ROOT / "datasets/patterns/cusick_disc.obj").read_text().splitlines()
    n_v = sum(1 for l in obj if l.startswith("v "))
    n_f = sum(1 for l in obj if l.startswith("f "))
    r = drapelab.simulate(scene)
    assert r.status == "converged"
    assert r.positions.shape == (n_v, 3) and (r.nx, r.ny) == (n_v, 1)
    assert r.triangles.shape == (n_f, 3) and r.present.all()
    assert r.run["self_contact"]["crossing_edges"] == 0
    m = drapelab.measure_drape(r)
    assert abs(m["drape_coefficient_pct"] - r.run["drape"]["drape_coefficient_pct"]) < 1.0


def test_a_restart_from_a_result_continues_its_run_in_zero_iterations():
    # sphere_wool's solve stiffens its self-contact barrier; the restart takes that up (issue 92).
    sphere = ROOT / "datasets/scenes/sphere_wool.toml"
    first = drapelab.simulate(sphere)
    assert first.converged and first.run["self_contact"]["kappa_growth"] > 1
    again = drapelab.simulate(sphere, start=first)
    assert again.report["iterations"] == 0
    assert np.abs(again.positions - first.positions).max() <= 1e-12
    assert again.run["start"]["kappa_growth_taken_up"] == first.run["self_contact"]["kappa_growth"]


def test_read_scene_round_trips_a_scene_with_relative_mesh_and_fabric_paths(tmp_path, monkeypatch):
    # Read where the scene is, simulated from another folder: the files it names still resolve.
    mesh_scene = ROOT / "datasets/bodies/sphere_wool_mesh.toml"
    table = drapelab.read_scene(mesh_scene)
    assert pathlib.Path(table["obstacles"][0]["mesh"]).is_absolute()
    monkeypatch.chdir(tmp_path)
    a = drapelab.simulate(table, {"cloth.nx": 11, "cloth.ny": 11})
    b = drapelab.simulate(mesh_scene, {"cloth.nx": 11, "cloth.ny": 11})
    assert a.converged and np.array_equal(a.positions, b.positions)
    # A scene naming its fabric by a relative path.
    sub = tmp_path / "sub"
    sub.mkdir()
    (sub / "wool.toml").write_text((ROOT / "datasets/fabrics/wool_seed003.toml").read_text())
    text = (ROOT / "datasets/scenes/sphere_wool.toml").read_text()
    head, rest = text.split("[material.continuum]", 1)
    tail = rest[rest.index("\n["):]
    (sub / "scene.toml").write_text(head + '[material]\nfabric = "wool.toml"\n' + tail)
    table = drapelab.read_scene(sub / "scene.toml")
    assert pathlib.Path(table["material"]["fabric"]).is_absolute()
    c = drapelab.simulate(table, {"cloth.nx": 11, "cloth.ny": 11})
    d = drapelab.simulate(sub / "scene.toml", {"cloth.nx": 11, "cloth.ny": 11})
    assert c.converged and np.array_equal(c.positions, d.positions)


def test_differences_of_restarted_drapes_are_the_sensitivity():
    # Issue 92 through the Python API: central differences of drapes restarted from the drape at
    # θ(1 ± 1e-4) against its sensitivity, the free turn about the sphere's axis projected out.
    sphere = ROOT / "datasets/scenes/sphere_wool.toml"
    key = "material.continuum.bending_warp_gf_cm2_per_cm"
    first = drapelab.simulate(sphere, sensitivity=[key])
    theta, h = 0.083, 0.083e-4
    hi = drapelab.simulate(sphere, {key: theta + h}, start=first)
    lo = drapelab.simulate(sphere, {key: theta - h}, start=first)
    fd = (hi.positions - lo.positions) / (2 * h)
    d = first.sensitivity(key)
    (mode,) = first.neutral_modes
    turn = np.cross(np.array(mode["axis"]), first.positions - np.array(mode["through_m"]))

    def orth(v):
        return v - turn * (np.sum(v * turn) / np.sum(turn * turn))

    rel = np.linalg.norm(orth(d) - orth(fd)) / np.linalg.norm(orth(fd))
    assert rel <= 1e-4, rel
