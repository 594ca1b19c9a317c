"""The Python package against the CLI (the same library): files equal to the last digit, every
exception type, nothing written on bad input, a study, the linear model's poles."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import flexstar


def cli_run(cli, root, tmp, *args):
    subprocess.run([cli, "run", *args, "--out", str(tmp)], cwd=root, check=True, capture_output=True)


@pytest.mark.parametrize("solver", ["amm", "fem"])
def test_files_equal_cli(cli, root, tmp_path, solver):
    exp = flexstar.Experiment.load(root / "configs/case3.toml")
    run = flexstar.run(exp, solver=solver)
    run.save(tmp_path / "py")
    cli_run(cli, root, tmp_path / "cli", "configs/case3.toml", "--solver", solver)
    stem = run.stem
    for suffix in (".csv", "-shapes.csv"):
        a = (tmp_path / "py/case3" / f"{stem}{suffix}").read_bytes()
        b = (tmp_path / "cli/case3" / f"{stem}{suffix}").read_bytes()
        assert a == b, f"{stem}{suffix} differs from the CLI's"
    import json

    cli_meta = json.loads((tmp_path / "cli/case3" / f"{stem}.json").read_text())
    for k in ("date", "wall_s", "commit"):
        cli_meta.pop(k, None)
        run.meta.pop(k, None)
    assert run.meta == cli_meta
    header = (tmp_path / "cli/case3" / f"{stem}.csv").read_text().splitlines()[0].split(",")
    assert run.columns == header


def test_forces_array_equals_cli_forces_file(cli, root, tmp_path):
    """Direct dynamics: forces= an array equals --forces FILE of the same samples."""
    exp = flexstar.Experiment.load(root / "configs/case3.toml")
    inverse = flexstar.run(exp, solver="amm")
    csv = pathlib.Path(inverse.save(tmp_path / "inv")[0])
    forces = np.column_stack([inverse[c] for c in ("t", "Fa1", "Fa2", "Fa3")])
    direct = flexstar.run(exp, solver="amm", forces=forces)
    direct.save(tmp_path / "py")
    cli_run(cli, root, tmp_path / "cli", "configs/case3.toml", "--solver", "amm", "--forces", str(csv))
    name = f"{direct.stem}.csv"
    assert (tmp_path / "py/case3" / name).read_bytes() == (tmp_path / "cli/case3" / name).read_bytes()


def test_roundtrip_dict_and_with_values(root):
    exp = flexstar.Experiment.load(root / "configs/case3.toml")
    again = flexstar.Experiment.from_dict(exp.to_dict(), source=str(root / "configs/case3.toml"))
    assert np.array_equal(flexstar.run(exp)["w1tip"], flexstar.run(again)["w1tip"])
    lp = exp.with_values({"robot.Lp": 0.04})
    assert lp.to_dict()["robot"]["Lp"] == 0.04
    assert exp.to_dict()["robot"].get("Lp") != 0.04


def test_a_robot_as_built_from_a_dict(root):
    """A robot as built given as a dict (per-beam lists, weld angles, an uneven base): its run
    differs from the paper robot's, and its modes at a pose agree between the AMM and the
    independent FEM (docs/modes.md, a robot as built)."""
    exp = flexstar.Experiment.load(root / "configs/case3.toml")
    d = exp.to_dict()
    d["robot"]["L"] = [0.5, 0.47, 0.53]
    d["robot"]["weld_deg"] = [0, 121.5, 238]
    d["robot"].pop("d", None)
    d["base"] = {"sides": [0.63, 0.6, 0.64]}
    built = flexstar.Experiment.from_dict(d, source=str(root / "configs/case3.toml"))
    assert built.to_dict()["robot"]["L"] == [0.5, 0.47, 0.53]
    run = flexstar.run(built)
    assert not np.array_equal(run["w2tip"], flexstar.run(exp)["w2tip"])
    m = flexstar.modal(built, at=0.3, modes=4)
    np.testing.assert_allclose(m["amm_hz"], m["fem_hz"], rtol=0.01)
    # one beam by the sweeps' per-beam key: the others keep the file's value
    one = exp.with_values({"robot.L[2]": 0.47})
    assert one.to_dict()["robot"]["L"] == [0.5, 0.47, 0.5]


@pytest.mark.parametrize(
    "call, key",
    [
        (lambda e: e.with_values({"robot.nope": 1.0}), "robot.nope"),
        (lambda e: e.with_values({"robot.Lp": -1.0}), "robot.Lp"),
        (lambda e: flexstar.run(e, solver="fem", elements=7), "fem.elements"),
        (lambda e: flexstar.run(e, solver="xyz"), None),
        (lambda e: flexstar.run(e, tol=float("nan")), None),
        (lambda e: flexstar.run(e, modes=-1), None),
        (lambda e: flexstar.run(e, forces=np.zeros((3, 3))), None),
        (lambda e: flexstar.run(e, forces=np.array([[0.0, 0, 0, 0], [0.0, 1, 1, 1]])), None),
        (lambda e: flexstar.modal(e, at=99.0), None),
    ],
)
def test_config_errors(root, tmp_path, monkeypatch, call, key):
    monkeypatch.chdir(tmp_path)
    exp = flexstar.Experiment.load(root / "configs/case3.toml")
    with pytest.raises(flexstar.ConfigError) as info:
        call(exp)
    assert isinstance(info.value, ValueError)
    if key is not None:
        # a file's key is named as the key, a keyword's value as its argument (the CLI's flag)
        assert info.value.key == key and key.split(".")[-1] in str(info.value), info.value
    assert list(tmp_path.iterdir()) == [], "nothing is written on bad input"


def test_config_error_names_file_and_line():
    with pytest.raises(flexstar.ConfigError, match="unknown field `x`"):
        flexstar.Experiment.from_toml("x = 1")


def test_infeasible_motion(root):
    exp = flexstar.Experiment.load(root / "configs/case3.toml")
    with pytest.raises(flexstar.InfeasibleMotion, match="outside the workspace"):
        flexstar.linearize(exp, pose=(0.9, 0.9, 0.0))
    fast = exp.with_values({"trajectory.s1": [0.0, 0.0, 100.0]})
    with pytest.raises(flexstar.InfeasibleMotion) as info:
        flexstar.run(fast)
    assert 0.0 <= info.value.t <= 0.5


def test_solver_error_on_unwritable_output(root):
    run = flexstar.run(flexstar.Experiment.load(root / "configs/case3.toml"))
    with pytest.raises(flexstar.SolverError):
        run.save("/proc/flexstar-cannot-write")


def test_poles_equal_free_modal_frequencies(root):
    """The linear model's poles (an eigenvalue problem of A) equal `modal`'s free-slider
    frequencies (the AMM's generalized eigenproblem), rigid modes at 0 Hz included."""
    exp = flexstar.Experiment.load(root / "configs/case3.toml")
    lin = flexstar.linearize(exp, at=0.3)
    m = flexstar.modal(exp, at=0.3, sliders="free", modes=6)
    poles = np.linalg.eigvals(lin.A)
    f = np.sort(np.abs(poles.imag)) / (2 * np.pi)
    elastic = f[::2][m["rigid"]:][:6]
    np.testing.assert_allclose(elastic, m["amm_hz"][m["rigid"]:], rtol=1e-8)


def test_study(root, tmp_path):
    study = tmp_path / "lp.toml"
    study.write_text(
        f'name = "lp"\nbase = "{root / "configs/case3.toml"}"\nsolvers = ["amm"]\n\n'
        '[[vary]]\nkey = "robot.Lp"\nvalues = [0.02, 0.03, 0.04]\n'
    )
    df = flexstar.sweep(study, tmp_path / "out", jobs=2)
    assert len(df) == 3
    # every row equals a single run of the same case
    for lp in (0.02, 0.04):
        row = df[np.isclose(df["robot.Lp"], lp)]
        assert len(row) == 1


def test_freqmap_equals_modal(root):
    """A map point's frequencies equal modal's AMM ones at that pose (sliders locked)."""
    pd = pytest.importorskip("pandas")
    exp = flexstar.Experiment.load(root / "configs/case1.toml")
    df = flexstar.freqmap(exp, gx=(-0.02, 0.02, 2), gy=(-0.02, 0.02, 2), modes=2)
    assert isinstance(df, pd.DataFrame) and len(df) == 4
    row = df.iloc[0]
    m = flexstar.modal(exp, pose=(row["Gx"], row["Gy"], 0.0), modes=2)
    np.testing.assert_allclose([row["f1"], row["f2"]], m["amm_hz"][:2], rtol=1e-9)


def test_compare_writes_the_cli_table(root, tmp_path):
    res = flexstar.compare(root / "configs/case3.toml", tmp_path, figures=False)
    assert pathlib.Path(res["compare_csv"]).exists()
    report = (pathlib.Path(res["dir"]) / "compare.json").read_text()
    assert res["behaviour"] in report, "the behaviour of G is the one compare.json reports"


def test_linearize_settings_and_names(root):
    """linearize's settings (docs/modes.md): K elastic modes and locked sliders give 2 K states
    named eta1..etaK, etad1..etadK; the names are those of the Rust model (the CLI's
    statespace.json); the eigenvalues of A equal +- i omega of `modal`'s locked frequencies; a
    servo experiment is closed-loop by default, and ``loop="closed"`` without a servo is refused."""
    exp = flexstar.Experiment.load(root / "configs/case3.toml")
    lin = flexstar.linearize(exp, at=0.3, modes=6, sliders="locked")
    assert lin.A.shape == (12, 12) and lin.B.shape == (12, 3) and lin.C.shape == (6, 12)
    assert lin.states == [f"eta{k}" for k in range(1, 7)] + [f"etad{k}" for k in range(1, 7)]
    assert lin.inputs == ["sdd1", "sdd2", "sdd3"]
    assert lin.outputs == ["w1tip", "w2tip", "w3tip", "w1G", "w2G", "w3G"]
    assert (lin.sliders, lin.loop, lin.rigid) == ("locked", "open", 0)
    m = flexstar.modal(exp, at=0.3, sliders="locked", modes=6)
    f = np.sort(np.abs(np.linalg.eigvals(lin.A).imag))[::2] / (2 * np.pi)
    np.testing.assert_allclose(f, m["amm_hz"], rtol=1e-8)
    free = flexstar.linearize(exp, at=0.3)
    assert free.inputs == ["Fa1", "Fa2", "Fa3"] and free.outputs[3] == "w1tip"
    assert len(free.states) == free.A.shape[0] == 2 * (3 + 20)
    servo = flexstar.linearize(flexstar.Experiment.load(root / "configs/servo/case3-servo.toml"), at=0.3, modes=4)
    assert servo.loop == "closed" and servo.inputs[0] == "s1ref" and servo.outputs[-1] == "e3"
    assert np.all(np.linalg.eigvals(servo.A).real < 0)
    with pytest.raises(flexstar.ConfigError, match="servo"):
        flexstar.linearize(exp, at=0.3, loop="closed")
    with pytest.raises(flexstar.ConfigError, match="loop"):
        flexstar.linearize(exp, at=0.3, loop="shut")
    try:
        import control  # noqa: F401
    except ImportError:
        return
    sys = lin.to_control()
    assert list(sys.state_labels) == lin.states and list(sys.input_labels) == lin.inputs


def test_stuck_sleeves_in_modal_and_linearize(root):
    """``sleeves="stuck"`` (docs/modes.md, stuck sleeves): every frequency at or above the sliding
    one, mode by mode (Rayleigh: a constraint added), no rigid mode with free sliders; the
    locked-slider linear model's states end with the sliders (Eqs. S4-S6), its elastic
    eigenvalues are ``modal``'s stuck frequencies, and a bad name is refused."""
    exp = flexstar.Experiment.load(root / "configs/case3.toml")
    sliding = flexstar.modal(exp, at=0.3, sliders="locked", modes=6)
    stuck = flexstar.modal(exp, at=0.3, sliders="locked", modes=6, sleeves="stuck")
    assert (sliding["sleeves"], stuck["sleeves"]) == ("sliding", "stuck")
    assert np.all(stuck["amm_hz"] >= sliding["amm_hz"] * (1 - 1e-9))
    assert np.all(stuck["fem_hz"] >= sliding["fem_hz"] * (1 - 1e-9))
    assert flexstar.modal(exp, at=0.3, sliders="free", modes=6, sleeves="stuck")["rigid"] == 0
    lin = flexstar.linearize(exp, at=0.3, modes=6, sliders="locked", sleeves="stuck")
    assert lin.sleeves == "stuck" and lin.A.shape == (18, 18) and lin.B.shape == (18, 3)
    assert lin.states[12:] == ["s1", "s2", "s3", "sd1", "sd2", "sd3"]
    f = np.sort(np.abs(np.linalg.eigvals(lin.A[:12, :12]).imag))[::2] / (2 * np.pi)
    np.testing.assert_allclose(f, stuck["amm_hz"], rtol=1e-8)
    with pytest.raises(flexstar.ConfigError, match="sleeves"):
        flexstar.linearize(exp, at=0.3, sleeves="glued")


def test_verify_reproduces_the_cli_table_and_checks(root, cli, tmp_path):
    """flexstar.verify() against `flexstar verify`: the same Table I (markdown, to the last
    digit) and the same number of checks, all holding."""
    res = flexstar.verify(tmp_path / "py")
    subprocess.run([cli, "verify", "--out", str(tmp_path / "cli"), "--no-figures", "--no-n-study"], check=True,
                   capture_output=True)
    assert res["failures"] == [], res["failures"]
    lines = (tmp_path / "cli" / "checks.txt").read_text().splitlines()
    cli_checks = [c for c in lines if c.startswith(("PASS ", "FAIL "))]
    assert all(c.startswith("PASS ") for c in cli_checks), cli_checks
    assert res["checks"] == len(cli_checks) > 0
    assert res["table_md"].strip() == (tmp_path / "cli" / "table1.md").read_text().strip()
    assert (tmp_path / "py" / "table1.md").read_text() == (tmp_path / "cli" / "table1.md").read_text()


def test_compare_errors_are_typed(root, tmp_path):
    """compare's refusals are the library's kinds: a bad file a ConfigError (a ValueError) naming
    the file and key, a motion that leaves the workspace an InfeasibleMotion with its time."""
    bad = tmp_path / "bad.toml"
    bad.write_text((root / "configs/case3.toml").read_text().replace("[robot]", "[robot]\nwrong_key = 1"))
    with pytest.raises(flexstar.ConfigError) as e:
        flexstar.compare(bad, tmp_path / "out")
    assert isinstance(e.value, ValueError) and "bad.toml" in str(e.value) and "wrong_key" in str(e.value)
    far = tmp_path / "far.toml"
    text = (root / "configs/case2.toml").read_text().replace("t_end = 0.4", "t_end = 0.5")
    assert "t_end = 0.5" in text
    far.write_text(text)
    with pytest.raises(flexstar.InfeasibleMotion) as e:
        flexstar.compare(far, tmp_path / "out")
    assert 0.4 < e.value.t < 0.5, e.value
    assert not (tmp_path / "out" / "case2").exists(), "nothing written"


def test_plan_matches_the_cli_contract(root, tmp_path):
    """flexstar.plan is `flexstar plan`: plan.csv with its header, the planned motion's residual
    peak of G on the FEM at most 1/20 of the plain quintic's (target move 1, docs/motions.md 6),
    the AMM within 10 % of the FEM on it, its Jacobians from the tangent; a bad plan is a
    ConfigError naming the key."""
    res = flexstar.plan(root / "configs/motions/plan-centre.toml", tmp_path)
    header = pathlib.Path(res["plan_csv"]).read_text().splitlines()[0]
    assert header == "t,Gx,Gy,theta,s1,s2,s3"
    (plain_amm, plain_fem), (amm, fem) = res["residual_G_peak_m"]["plain"], res["residual_G_peak_m"]["planned"]
    assert fem <= plain_fem / 20 and abs(amm - fem) <= 0.1 * fem
    assert abs(res["t_move"] - 0.42) < 1e-12
    # the bare robot's Jacobians come from the tangent-linear AMM (docs/motions.md 4.9), 12 columns each
    assert res["tangent_columns"] > 0 and res["tangent_columns"] % 12 == 0
    bad = tmp_path / "bad.toml"
    bad.write_text((root / "configs/motions/plan-centre.toml").read_text().replace("t_move = 0.42", "t_move = 0.42\npoints = 0"))
    with pytest.raises(flexstar.ConfigError) as e:
        flexstar.plan(bad, tmp_path / "out")
    assert "plan.points" in str(e.value) and "bad.toml" in str(e.value)


def test_saving_over_another_experiment_with_the_same_name_warns(root, tmp_path):
    """Two experiments with the same `name` share out/<name>/: saving over the other one's results
    warns (as the CLI says so on stderr); saving the same one again does not."""
    import warnings

    text = (root / "configs/case3.toml").read_text()
    a = flexstar.Experiment.from_toml(text, source=str(tmp_path / "a.toml"))
    b = flexstar.Experiment.from_toml(text.replace("E = 200e9", "E = 150e9"), source=str(tmp_path / "b.toml"))
    flexstar.run(a, solver="amm").save(tmp_path / "out")
    with pytest.warns(UserWarning, match="another experiment named `case3`"):
        flexstar.run(b, solver="amm").save(tmp_path / "out")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        flexstar.run(b, solver="amm").save(tmp_path / "out")


@pytest.mark.skipif(not os.environ.get("FLEXSTAR_EXPECT_WHEEL"), reason="only where CI installed the wheel")
def test_the_package_is_the_installed_wheel_and_needs_no_rust():
    """CI (.ci/run) installs the abi3 wheel into a fresh environment without cargo on PATH: the
    extension imported is the installed one, and no Rust toolchain is reachable."""
    import shutil
    import sysconfig

    site = pathlib.Path(sysconfig.get_paths()["purelib"]).resolve()
    ext = pathlib.Path(flexstar._flexstar.__file__).resolve()
    assert site in ext.parents, f"{ext} is not under {site}"
    assert ".abi3." in ext.name, ext.name
    assert shutil.which("cargo") is None and shutil.which("rustc") is None


@pytest.mark.parametrize("solver", ["amm", "fem"])
def test_run_sensors_encoder_is_the_rigid_slider_position(root, tmp_path, solver):
    """`run.sensors` (docs/sensors.md): an accelerometer at G gives `<name>_x`, `<name>_y`, an
    encoder reads slider 2's s_2(t) of the prescribed polynomial (evaluated here with numpy, not
    by the library), the arrays equal the `<stem>-sensors.csv` that `save` writes, and a run
    without sensors gives an empty dict."""
    exp = flexstar.Experiment.load(root / "configs/case3.toml")
    d = exp.to_dict()
    d["time"]["t_end"] = 0.05
    d["fem"]["elements"] = 120
    d["trajectory"]["s2"] = [0.01, 0.0, -0.4, 1.5]
    d["sensors"] = [
        {"name": "ga", "kind": "accelerometer", "at": "G", "axes": "fixed"},
        {"name": "enc", "kind": "encoder", "slider": 2},
    ]
    with_sensors = flexstar.Experiment.from_dict(d, source=str(root / "configs/case3.toml"))
    run = flexstar.run(with_sensors, solver=solver)
    s = run.sensors
    assert list(s) == ["t", "ga_x", "ga_y", "enc"]
    t = s["t"]
    np.testing.assert_allclose(t, run["t"], rtol=0, atol=1e-12)  # no rate_hz: the output times
    s2 = np.polynomial.polynomial.polyval(t, d["trajectory"]["s2"])
    np.testing.assert_allclose(s["enc"], s2, rtol=0, atol=1e-12)
    assert all(a.dtype == np.float64 and a.shape == t.shape for a in s.values())
    assert run.meta["column_units"]["ga_x"] == "m/s^2" and run.meta["column_units"]["enc"] == "m"
    files = run.save(tmp_path)
    csv = next(f for f in files if f.endswith("-sensors.csv"))
    header = pathlib.Path(csv).read_text().splitlines()[0].split(",")
    table = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert header == list(s)
    for k, name in enumerate(header):
        np.testing.assert_allclose(s[name], table[:, k], rtol=1e-12, atol=1e-300)
    d.pop("sensors")
    plain = flexstar.run(flexstar.Experiment.from_dict(d, source=str(root / "configs/case3.toml")), solver=solver)
    assert plain.sensors == {}


def test_plan_of_a_whole_cycle_reports_each_move_and_dwell(root, tmp_path):
    """flexstar.plan plans a cycle (`[plan] points`, docs/motions.md 4.12) as `flexstar plan`
    does: one entry per move and per dwell; each dwell's residual peaks are those of the runs'
    `-dwells.csv` files the command writes (read here); the planned cycle's table has the pose
    and slider columns. The planner's budget is cut to keep the test short: the 1/20 target of
    the cycle is checked by the Rust test of `flexstar plan` (tests/plan_cycle.rs)."""
    text = (root / "configs/motions/plan-pick-place.toml").read_text().replace("budget_s = 60", "budget_s = 2")
    cfg = tmp_path / "cycle.toml"
    cfg.write_text(text)
    res = flexstar.plan(cfg, tmp_path / "out")
    assert len(res["moves"]) == 2 and len(res["dwells"]) == 2
    assert [m["t_start"] for m in res["moves"]] == pytest.approx([0.0, 0.7])
    assert all(m["t_move"] == pytest.approx(0.4) for m in res["moves"])
    header = pathlib.Path(res["plan_csv"]).read_text().splitlines()[0]
    assert header == "t,Gx,Gy,theta,s1,s2,s3"
    for motion, stem in (("plain", "plain"), ("planned", "planned")):
        rows = (pathlib.Path(res["dir"]) / stem / "fem-dwells.csv").read_text().splitlines()
        cols = rows[0].split(",")
        peaks = [float(r.split(",")[cols.index("G_peak_m")]) for r in rows[1:]]
        assert [d[motion][1] for d in res["dwells"]] == pytest.approx(peaks, rel=1e-12)


def test_compare_lays_a_recording_over_the_runs(root, tmp_path):
    """flexstar.compare(..., measured=) is `flexstar compare --measured` (docs/measured.md 1-3): the
    bench robot's FEM recording laid over its own runs gives the FEM an error at the noise's level,
    and the free decay's identified modes lie within 0.5 % of the AMM's frequencies at the final
    pose, a second model that never saw the recording."""
    import json

    truth = flexstar.Experiment.load(root / "configs/measured/truth.toml")
    flexstar.run(truth, solver="fem").save(tmp_path / "rec")
    rec = tmp_path / "rec/truth/fem-sensors.csv"
    res = flexstar.compare(root / "configs/measured/truth.toml", tmp_path / "cmp", measured=rec)
    m = json.loads((pathlib.Path(res["dir"]) / "compare.json").read_text())["measured"]
    fem_acc = [e for e in m["errors"] if e["run"] == "fem" and e["unit"] == "m/s^2"]
    assert len(fem_acc) == 4 and all(e["rms"] < 1e-12 for e in fem_acc), fem_acc
    model = m["modes_hz"]
    assert len(m["identified"]) >= 3, m
    for mode in m["identified"][:3]:
        assert min(abs(mode["f_hz"] / f - 1.0) for f in model) < 5e-3, (mode, model)


def test_fit_matches_the_cli_contract(root, tmp_path):
    """flexstar.fit is `flexstar fit` (docs/measured.md section 4): fit.json's content as a dict,
    the calibrated Experiment that runs, the estimates within the targets of 4.11 on the FEM's
    recording of the bench robot; a [fit] with E and I both is a ConfigError naming the product
    the data fix."""
    truth = flexstar.Experiment.load(root / "configs/measured/truth.toml")
    flexstar.run(truth, solver="fem").save(tmp_path / "rec")
    rec = tmp_path / "rec/truth/fem-sensors.csv"
    res = flexstar.fit(root / "configs/measured/nominal.toml", rec, tmp_path / "out")
    assert res["converged"] and res["calibrated"] and res["identifiability"]["verdict"] == "identifiable"
    # its Jacobians from the tangent-linear AMM (docs/measured.md 4.5, Eq. LS9b)
    assert res["jacobians"]["total"] > 0 and res["jacobians"]["by_tangent"] == res["jacobians"]["total"]
    truths = {"payload.mass": (0.4, 0.02), "payload.J": (1.5e-3, 0.02), "damping.zeta": (0.02, 0.05), "robot.E": (190e9, 0.01)}
    for p in res["parameters"]:
        value, target = truths[p["key"]]
        assert abs(p["estimate"] - value) <= target * value, p
        lo, hi = p["interval_95"]
        assert lo < p["estimate"] < hi
        # the reported interval holds the truth (docs/measured.md 4.7, Eq. LS19)
        assert lo <= value <= hi, p
        assert p["standard_error_correlated"] >= p["standard_error"] > 0, p
    assert all(c["rms_fem"] < 1.2 * c["noise"] for c in res["fem_check"]["channels"]), res["fem_check"]
    assert pathlib.Path(res["fit_toml"]).exists()
    cal = res["experiment"]
    assert cal.to_dict()["payload"]["mass"] == res["parameters"][0]["estimate"]
    assert len(flexstar.run(cal, solver="amm")["t"]) == 1301
    bad = tmp_path / "bad.toml"
    text = (root / "configs/measured/nominal.toml").read_text()
    bad.write_text(text.replace('{ key = "payload.J", lo = 2e-4, hi = 5e-3 },', '{ key = "robot.I", lo = 1e-12, hi = 5e-12 },'))
    with pytest.raises(flexstar.ConfigError) as e:
        flexstar.fit(bad, rec, tmp_path / "out")
    assert "robot.I^1.00 x robot.E^1.00" in str(e.value) and "bad.toml" in str(e.value)
