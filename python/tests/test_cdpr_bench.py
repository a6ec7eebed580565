"""cdpr_bench from Python against the CLI it wraps: the same scenario gives the same metrics
and samples bit for bit, a sweep (threads, or Dask worker processes) the same records, and bad
input a ScenarioError naming the key."""

import csv
import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import cdpr_bench

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHORT = {"simulation": {"t_final": 1.2}, "analysis": {"modes": "off"}}
GRID = """
[scenario]
simulation = { t_final = 1.0 }
analysis = { modes = "off" }
[axes]
"robot.effector_mass" = { from = 0.5, to = 2.0, steps = 3, scale = "log" }
"trajectory.t2" = [0.2, 0.3]
"""


def xtask():
    """The CLI binary: $XTASK, else the one `cargo test` built (or `cargo xtask`)."""
    if "XTASK" in os.environ:
        return os.environ["XTASK"]
    for profile in ("debug", "release"):
        path = ROOT / "target" / profile / "xtask"
        if path.exists():
            return str(path)
    pytest.fail("no xtask binary: run `cargo build -p xtask` or set XTASK")


def cli(*args):
    done = subprocess.run([xtask(), *args], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def without_wall(path):
    return [line.split('"wall_s":')[0] for line in path.read_text().splitlines()]


def test_simulate_equals_the_cli_bit_for_bit(tmp_path):
    scenario = tmp_path / "s.toml"
    scenario.write_text('[simulation]\nt_final = 1.2\n[analysis]\nmodes = "off"\n')
    cli("simulate", "--scenario", str(scenario), "--out", str(tmp_path / "out"))
    theirs = json.loads((tmp_path / "out" / "metrics.json").read_text())
    metrics, series = cdpr_bench.simulate(str(scenario))
    skip = {"wall_s", "provenance", "units", "modal_analysis_note"}
    for key, value in theirs.items():
        if key not in skip:
            assert metrics[key] == value, key
    with open(tmp_path / "out" / "timeseries.csv") as f:
        rows = list(csv.reader(f))
    # The CSV's headings carry units ("t [s]"); the series' keys are the channels' names.
    names = [heading.split(" [")[0] for heading in rows[0]]
    values = np.array(rows[1:], dtype=float)
    assert set(names) == set(series)
    for k, name in enumerate(names):
        assert isinstance(series[name], np.ndarray)
        assert np.array_equal(series[name], values[:, k]), name


def test_every_form_of_a_scenario_is_the_same_run(tmp_path):
    text = '[simulation]\nt_final = 1.2\n[analysis]\nmodes = "off"\n'
    path = tmp_path / "s.toml"
    path.write_text(text)
    runs = [cdpr_bench.simulate(s) for s in (SHORT, text, str(path), path)]
    for metrics, series in runs[1:]:
        for key in runs[0][0]:
            if key != "wall_s":
                assert metrics[key] == runs[0][0][key], key
        assert np.array_equal(series["z"], runs[0][1]["z"])


def test_model_override_and_modes():
    metrics, _ = cdpr_bench.simulate(SHORT, model="lumped")
    assert metrics["model"] == "lumped"
    analysis = cdpr_bench.modes({}, x=0.6)
    # MODELS.md §3: the elastic closed loop's vertical mode at x = 0.6, 20.3738 rad/s.
    vertical = [m for m in analysis["modes"] if m["kind"] == "Vertical"]
    assert abs(vertical[0]["mode"]["omega"] - 20.3738) < 1e-3
    open_loop = cdpr_bench.modes({}, x=0.6, loop="open")
    assert open_loop["feedback"] == "Open"


@pytest.mark.parametrize(
    "scenario, needles",
    [
        ({"robot": {"effector_mass": -1.0}}, ["robot.effector_mass", "-1"]),
        ({"robot": {"effector_mas": 1.0}}, ["effector_mas"]),
        ({"model": {"kind": "spring"}}, ["spring"]),
        ("/no/such/scenario.toml", ["/no/such/scenario.toml"]),
    ],
)
def test_bad_scenarios_raise_scenario_error_naming_the_key(scenario, needles):
    with pytest.raises(cdpr_bench.ScenarioError) as e:
        cdpr_bench.simulate(scenario)
    for n in needles:
        assert n in str(e.value)
    assert isinstance(e.value, ValueError)


def test_a_run_that_fails_raises_simulation_error():
    with pytest.raises(cdpr_bench.SimulationError, match="slack"):
        cdpr_bench.simulate({"trajectory": {"t2": 0.02}, "simulation": {"t_final": 0.1}})


def test_bad_grids_and_shards_raise_scenario_error(tmp_path):
    with pytest.raises(cdpr_bench.ScenarioError, match="has no points"):
        cdpr_bench.grid_points('[axes]\n"robot.effector_mass" = []\n')
    with pytest.raises(cdpr_bench.ScenarioError, match="point 1"):
        cdpr_bench.grid_points('[axes]\n"trajectory.t2" = [0.2, -0.1]\n')
    with pytest.raises(cdpr_bench.ScenarioError, match="3/2"):
        cdpr_bench.sweep(GRID, tmp_path / "o", shard="3/2")


def test_sweep_equals_the_cli_sweep(tmp_path):
    grid = tmp_path / "grid.toml"
    grid.write_text(GRID)
    cli("sweep", "--grid", str(grid), "--out", str(tmp_path / "cli"))
    records = cdpr_bench.sweep(str(grid), tmp_path / "py", jobs=2)
    assert [r["point"] for r in records] == list(range(6))
    assert without_wall(tmp_path / "cli" / "results.jsonl") == without_wall(
        tmp_path / "py" / "results.jsonl"
    )


def test_dask_local_cluster_gets_the_cli_records(tmp_path):
    import dask.distributed  # noqa: F401  (installed with the test extra; .ci/run does)
    grid = tmp_path / "grid.toml"
    grid.write_text(GRID)
    cli("sweep", "--grid", str(grid), "--out", str(tmp_path / "cli"))
    example = ROOT / "python" / "examples" / "dask_sweep.py"
    done = subprocess.run(
        [sys.executable, str(example), str(grid), str(tmp_path / "dask")],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    assert without_wall(tmp_path / "cli" / "results.jsonl") == without_wall(
        tmp_path / "dask" / "results.jsonl"
    )


def test_a_spatial_robot_runs_as_the_cli_does(tmp_path):
    scenario = ROOT / "examples" / "robots" / "hangprinter.toml"
    cli("simulate", "--scenario", str(scenario), "--out", str(tmp_path / "out"))
    theirs = json.loads((tmp_path / "out" / "metrics.json").read_text())
    metrics, series = cdpr_bench.simulate(str(scenario))
    assert metrics["cables"] == 4 and len(metrics["cable_tension_max"]) == 4
    for key, value in metrics.items():
        assert theirs[key] == value, key
    assert metrics["path_err_max_move"] < 1e-6
    with open(tmp_path / "out" / "timeseries.csv") as f:
        rows = list(csv.reader(f))
    names = [heading.split(" [")[0] for heading in rows[0]]
    values = np.array(rows[1:], dtype=float)
    assert {"x", "y", "z", "T4", "l0_4", "saturated"} <= set(series)
    for k, name in enumerate(names):
        assert np.array_equal(series[name], values[:, k]), name
