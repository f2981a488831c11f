"""Design-load campaigns (issue 39): a case table read and checked before any work, each
case's scene, cases run in batches whose answers equal each case's own run, results kept
per case so that a killed campaign restarts where it stopped and shards add up to one
run, failures recorded while the others go on, and the tables over cases and seeds."""

import csv
import json
import shutil
import socket
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import jaxcable as jc
from jaxcable._campaign.campaign import run_campaign
from jaxcable._campaign.cases import case_scene, read_cases
from jaxcable._campaign.store import cell
from jaxcable._cli import main as cli_main
from jaxcable.io import SceneError
from jaxcable.io._run import run_scene

# Two chains from anchors to a held fairlead, in a regular wave, an irregular sea and a
# current: small enough to compile and run in seconds.
SCENE = """
title = "Two chains to a held fairlead, in waves and a current"

[water]
depth = 50.0
current = [0.2, 0.0, 0.0]
wave_ramp = 1.0

[[waves]]
theory = "airy"
height = 1.0
period = 6.0

[[waves]]
spectrum = "jonswap"
significant_height = 1.0
peak_period = 7.0
components = 40
frequencies = [0.55, 3.5]
seed = 1

[simulation]
duration = 2.0
dt_out = 0.1
mass_matrix = "lumped"

[line_types.chain]
mass_per_length = 20.0
diameter = 0.03
axial_stiffness = 5.0e7
axial_damping_ratio = 0.5
minimum_breaking_load = 1.0e6
fatigue_curve = "api_stud_chain"

[line_types.heavy]
mass_per_length = 40.0
diameter = 0.04
axial_stiffness = 5.0e7
axial_damping_ratio = 0.5

[line_types.soft]  # whose drag in a strong current outgrows its stiffness
mass_per_length = 1.0
diameter = 0.03
axial_stiffness = 1.0e3

[points.west]
type = "fixed"
position = [-80.0, 0.0, -50.0]

[points.east]
type = "fixed"
position = [80.0, 0.0, -50.0]

[points.top]
type = "coupled"
position = [0.0, 0.0, -5.0]

[[lines]]
name = "w"
type = "chain"
from = "west"
to = "top"
length = 100.0
segments = 4

[[lines]]
name = "e"
type = "chain"
from = "east"
to = "top"
length = 100.0
segments = 4

[output]
channels = ["FairTen1", "FairTen2"]
"""

# Three sea states of one structure (two seeds of one of them) and a damaged case.
CASES = """\
case,wave_height,seed,removed
calm,1.0,1,
rough,3.0,1,
calm_seed2,1.0,2,
damaged,1.0,1,e
"""


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("campaign")
    (folder / "scene.toml").write_text(SCENE)
    (folder / "cases.csv").write_text(CASES)
    return folder


@pytest.fixture(scope="module")
def campaign(files):
    """The campaign run once, two cases a batch: `(scene, cases, result)`."""
    scene = jc.read_scene(files / "scene.toml")
    cases = read_cases(files / "cases.csv")
    result = run_campaign(scene, cases, files / "out", table_folder=files, batch=2)
    return scene, cases, result


def _table(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


# --------------------------------------------------------------------------------------
# The case table


def test_csv_and_toml_tables_read_alike(tmp_path):
    (tmp_path / "cases.csv").write_text("case,significant_height,seed,length.w,type.e\na,2.5,3,90,heavy\nb,,4,,\n")
    (tmp_path / "cases.toml").write_text(
        textwrap.dedent("""
        [[case]]
        case = "a"
        significant_height = 2.5
        seed = 3
        length = {w = 90}
        "type.e" = "heavy"

        [[case]]
        case = "b"
        seed = 4
        """)
    )
    from_csv, from_toml = read_cases(tmp_path / "cases.csv"), read_cases(tmp_path / "cases.toml")
    assert [(c.name, c.values) for c in from_csv] == [(c.name, c.values) for c in from_toml]
    assert from_csv[0].values == {"significant_height": 2.5, "seed": 3, "length.w": 90.0, "type.e": "heavy"}
    assert from_csv[1].values == {"seed": 4}  # empty cells keep the scene's values
    assert isinstance(from_csv[0].values["seed"], int)


def test_cases_are_named_by_row_without_a_case_column(tmp_path):
    (tmp_path / "cases.csv").write_text("wave_height\n1.0\n2.0\n")
    assert [c.name for c in read_cases(tmp_path / "cases.csv")] == ["case0001", "case0002"]


@pytest.mark.parametrize(
    ("table", "expected"),
    [
        ("case,wave_hieght\na,1\n", "unknown column 'wave_hieght'"),
        ("case,wave_height\na,high\n", "case row 1: wave_height must be a finite number, got 'high'"),
        ("case,wave_height\na,nan\n", "wave_height must be a finite number"),
        ("case,seed\na,1.5\n", "seed must be a whole number"),
        ("case,wave_height\na,1\na,2\n", "case row 2: case 'a' is named already"),
        ("case,wave_height\na,1,3\n", "case row 1: 3 fields under a header of 2 columns"),
        ("case,wave_height\n", "the case table has no cases"),
        ("case,wave_height,wave_height\na,1,2\n", "column 'wave_height' appears twice"),
        ("case,wave_height\na/b,1\n", "case name 'a/b' must be letters"),
        ("case,length\na,1\n", "unknown column 'length'"),
    ],
)
def test_bad_tables_are_refused_naming_row_and_column(tmp_path, table, expected):
    (tmp_path / "cases.csv").write_text(table)
    with pytest.raises(SceneError, match=expected.replace("(", r"\(").replace(")", r"\)")):
        read_cases(tmp_path / "cases.csv")


def test_a_case_sets_the_scene(files):
    scene = jc.read_scene(files / "scene.toml")
    table = files / "set.csv"
    table.write_text(
        "case,wave_height,wave_period,heading,significant_height,peak_period,seed,current_speed,current_heading,"
        "length.w,type.e\nx,2.0,8.0,30,3.0,9.0,7,0.5,90,110,heavy\n"
    )
    (case,) = read_cases(table)
    changed = case_scene(scene, case, files)
    regular, sea = changed.water.waves
    assert (regular.height, regular.period, regular.heading) == (2.0, 8.0, 30.0)
    assert (sea.significant_height, sea.peak_period, sea.seed, sea.heading) == (3.0, 9.0, 7, 30.0)
    np.testing.assert_allclose(changed.water.current, (0.0, 0.5, 0.0), atol=1e-15)
    assert changed.lines[0].length == 110.0 and changed.lines[1].line_type == "heavy"
    assert scene.lines[0].length == 100.0  # the scene itself is unchanged


def test_a_removed_line_takes_its_lone_points(files):
    scene = jc.read_scene(files / "scene.toml")
    table = files / "removed.csv"
    table.write_text("case,removed\nx,w\n")
    (case,) = read_cases(table)
    damaged = case_scene(scene, case, files)
    assert [line.name for line in damaged.lines] == ["e"]
    assert [p.name for p in damaged.points] == ["east", "top"]
    assert (damaged.lines[0].start, damaged.lines[0].end) == (0, 1)
    damaged.build()


@pytest.mark.parametrize(
    ("row", "expected"),
    [
        ("length.x\n10", "length.x: the scene has no line 'x'; its lines: w, e"),
        ("type.w\nsteel", "type.w: the scene has no line type 'steel'"),
        ("removed\nw;e", "removed takes out every line"),
        ("removed\nq", "removed: the scene has no line 'q'"),
        ("length.w\n-5", "length.w must be a positive length"),
    ],
)
def test_a_row_the_scene_cannot_take_is_refused(files, row, expected):
    scene = jc.read_scene(files / "scene.toml")
    table = files / "bad.csv"
    table.write_text(row + "\n")
    (case,) = read_cases(table)
    with pytest.raises(SceneError, match=expected):
        case_scene(scene, case, files)


def test_sea_columns_need_a_sea(files, tmp_path):
    calm = SCENE.split("[[waves]]")[0] + "[simulation]" + SCENE.split("[simulation]")[1]
    (tmp_path / "calm.toml").write_text(calm)
    scene = jc.read_scene(tmp_path / "calm.toml")
    table = tmp_path / "sea.csv"
    table.write_text("significant_height\n2\n")
    (case,) = read_cases(table)
    with pytest.raises(SceneError, match="significant_height set.* an irregular sea, but the scene has none"):
        case_scene(scene, case, tmp_path)


# --------------------------------------------------------------------------------------
# Running


def test_each_case_equals_its_own_run(files, campaign):
    """A case run in a batch gives what `jaxcable run` gives for it alone, to rounding."""
    scene, cases, result = campaign
    assert result.ran == ("calm", "rough", "calm_seed2", "damaged") and not result.failed
    for case in cases:
        alone = run_scene(case_scene(scene, case, files))
        with xr.open_dataset(result.folder / "cases" / f"{case.name}.nc") as held:
            np.testing.assert_allclose(held["tension"].values, alone.tension, rtol=1e-10, atol=1e-6)
            assert list(held["line"].values) == [line.name for line in alone.built.scene.lines]
            assert held.attrs["case"] == case.name
            assert json.loads(held.attrs["case_values"]) == case.values
            assert held.attrs["jaxcable_version"] == jc.__version__
    # The rough sea loads the lines more than the calm one.
    rows = {row["case"]: row for row in _table(result.summary)}
    assert float(rows["rough"]["std.FairTen1"]) > 2 * float(rows["calm"]["std.FairTen1"])


def test_the_summary_has_a_row_per_case(campaign):
    _, _, result = campaign
    rows = _table(result.summary)
    assert [row["case"] for row in rows] == ["calm", "rough", "calm_seed2", "damaged"]
    assert list(rows[0])[:4] == ["case", "wave_height", "seed", "removed"]
    with xr.open_dataset(result.folder / "cases" / "rough.nc") as rough:
        k = list(rough["line"].values).index("w")
        assert float(rows[1]["largest_tension.w"]) == pytest.approx(float(rough["largest_tension"][k]), rel=1e-7)
        assert float(rows[1]["utilisation.w"]) == pytest.approx(float(rough["largest_tension"][k]) / 1e6, rel=1e-7)
        series = rough["FairTen1"].values
        assert float(rows[1]["maximum.FairTen1"]) == pytest.approx(series.max(), rel=1e-7)
        # The chain's fatigue (API RP 2SK's stud chain curve, m = 3) at its most damaged
        # segment, and that segment's damage-equivalent load at one cycle a second.
        damage, load = float(rough["fatigue_damage"][k]), float(rough["fatigue_equivalent_load"][k])
        assert float(rows[1]["fatigue_damage.w"]) == pytest.approx(damage, rel=1e-7) and damage > 0
        owner, times = rough["segment_line"].values, rough["time"].values
        worst = max(
            (rough["tension"].values[:, j] for j in np.flatnonzero(owner == k + 1)),
            key=lambda history: jc.damage_equivalent_load(history, 3.0, times[-1] - times[0]),
        )
        assert load == pytest.approx(jc.damage_equivalent_load(worst, 3.0, times[-1] - times[0]), rel=1e-12)
        assert float(rows[1]["fatigue_equivalent_load.w"]) == pytest.approx(load, rel=1e-7)
    # The damaged case has no line e and no FairTen2; the table leaves its cells empty.
    assert rows[3]["largest_tension.e"] == "" and rows[3]["maximum.FairTen2"] == ""
    assert rows[3]["largest_tension.w"] != ""


def test_seeds_of_one_sea_state_give_its_most_probable_maximum(campaign):
    _, _, result = campaign
    (group,) = _table(result.groups)
    assert group["cases"] == "calm calm_seed2" and group["seeds"] == "2"
    records = []
    for name in ("calm", "calm_seed2"):
        with xr.open_dataset(result.folder / "cases" / f"{name}.nc") as held:
            owner = held["segment_line"].values
            records.append(held["tension"].values[:, owner == 1].max(axis=1))
            times = held["time"].values
    fit = jc.extreme_statistics(np.stack(records), times)
    assert float(group["mpm_tension.w"]) == pytest.approx(float(fit.most_probable_maximum), rel=1e-7)
    channel = []
    for name in ("calm", "calm_seed2"):
        with xr.open_dataset(result.folder / "cases" / f"{name}.nc") as held:
            channel.append(held["FairTen1"].values)
    fit = jc.extreme_statistics(np.stack(channel), times)
    assert float(group["mpm.FairTen1"]) == pytest.approx(float(fit.most_probable_maximum), rel=1e-7)


def test_shards_and_a_restart_add_up_to_one_run(files, campaign, tmp_path):
    """Two shards into one folder, one of them killed after its first batch and run
    again, give the tables of one uninterrupted run."""
    scene, cases, whole = campaign
    folder = tmp_path / "sharded"

    def killed_after_first_batch(line):
        if line.startswith("campaign: running") and (folder / "cases").exists() and any((folder / "cases").iterdir()):
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_campaign(scene, cases, folder, table_folder=files, batch=1, shard=(0, 2), log=killed_after_first_batch)
    assert [p.stem for p in (folder / "cases").glob("*.nc")] == ["calm"]
    assert not list((folder / "cases").glob(".*"))  # no half-written file
    again = run_campaign(scene, cases, folder, table_folder=files, batch=2, shard=(0, 2))
    assert again.skipped == ("calm",) and again.ran == ("calm_seed2",)
    other = run_campaign(scene, cases, folder, table_folder=files, batch=2, shard=(1, 2))
    assert other.ran == ("rough", "damaged")
    assert _numbers(_table(other.summary)) == pytest.approx(
        _numbers(_table(whole.summary)), rel=1e-10, abs=1e-6, nan_ok=True
    )
    assert run_campaign(scene, cases, folder, table_folder=files).ran == ()


def _numbers(rows: list[dict[str, str]]) -> list[float]:
    return [float(v) if v else np.nan for row in rows for k, v in row.items() if k not in ("case", "removed")]


def test_a_folder_of_another_campaign_is_refused(files, campaign, tmp_path):
    scene, cases, result = campaign
    with pytest.raises(SceneError, match="holds a campaign of another scene or other settings"):
        run_campaign(scene, cases, result.folder, table_folder=files, duration=1.0)
    changed = files / "changed.csv"
    changed.write_text("case,wave_height,seed,removed\ncalm,1.5,1,\n")
    with pytest.raises(SceneError, match="holds a result for case 'calm' of another row"):
        run_campaign(scene, read_cases(changed), result.folder, table_folder=files)


def test_a_motion_table_short_of_the_duration_is_refused_before_any_case_runs(files, tmp_path):
    scene = jc.read_scene(files / "scene.toml")
    (tmp_path / "short.csv").write_text("time,x,y,z\n0,0,0,-5\n1,0,0,-5\n")
    table = tmp_path / "cases.csv"
    table.write_text("case,motion\nheld,\nmoved,short.csv\n")
    with pytest.raises(
        SceneError, match="case row 2: case moved: .*motion table covers 0 to 1 s, but the run needs 0 to 2 s"
    ):
        run_campaign(scene, read_cases(table), tmp_path / "out", table_folder=tmp_path)
    assert not list((tmp_path / "out" / "cases").glob("*"))


def test_a_failed_case_is_recorded_and_the_others_go_on(files, tmp_path):
    scene = jc.read_scene(files / "scene.toml")
    table = tmp_path / "cases.csv"
    # A soft line in a 5 m/s current has no equilibrium: its drag grows as it stretches.
    table.write_text("case,type.w,current_speed\nsoft,soft,5\nfine,,0.3\nfine2,,0.5\n")
    result = run_campaign(scene, read_cases(table), tmp_path / "out", table_folder=tmp_path, batch=2)
    assert list(result.failed) == ["soft"] and "found no equilibrium" in result.failed["soft"]
    assert sorted(p.stem for p in (tmp_path / "out" / "cases").glob("*.nc")) == ["fine", "fine2"]
    rows = {row["case"]: row for row in _table(result.summary)}
    assert "found no equilibrium" in rows["soft"]["failed"] and rows["fine"]["failed"] == ""
    # A restart does not run it again: it would fail again.
    assert run_campaign(scene, read_cases(table), tmp_path / "out", table_folder=tmp_path).ran == ()


# --------------------------------------------------------------------------------------
# The command line


def test_the_command_runs_a_campaign(files, campaign, capsys):
    shutil.copytree(campaign[2].folder, files / "copy")
    status = cli_main(["campaign", str(files / "scene.toml"), str(files / "cases.csv"), "--out", str(files / "copy")])
    out = capsys.readouterr().out
    assert status == 0, out
    assert "0 case(s) run, 0 failed, 4 finished before" in out
    copy = files / "copy"
    assert f"wrote {copy / 'summary.csv'}, {copy / 'groups.csv'}, {copy / 'report.html'}" in out


def test_safety_factors_are_judged_and_reported(files, campaign, capsys):
    """Each line's safety factor, MBL over its largest tension (over seeds, over the
    most probable maximum), against the required one: the chains here carry about
    16 kN against a 1 MN breaking load, a factor of about 63."""
    _, _, result = campaign
    rows = {row["case"]: row for row in _table(result.summary)}
    calm = rows["calm"]
    assert float(calm["safety_factor.w"]) == pytest.approx(1e6 / float(calm["largest_tension.w"]), rel=1e-7)
    assert result.shortfalls == ()  # 63 is well above 1.67
    argv = ["campaign", str(files / "scene.toml"), str(files / "cases.csv"), "--out", str(result.folder)]
    assert cli_main([*argv, "--tables-only", "--safety-factor", "100"]) == 0
    err = capsys.readouterr().err
    assert "warning: calm: line w's largest tension leaves a safety factor of 62." in err and "below 100" in err
    assert "warning: calm calm_seed2: line w's most probable maximum leaves a safety factor of" in err
    report = (result.folder / "report.html").read_text()
    assert "Below the required safety factor" in report and "calm_seed2" in report
    # Tensions in kN, as the headings say; the tables hold newtons.
    assert "<th>largest tension (kN), w</th>" in report
    assert f"<td>{cell(float(calm['largest_tension.w']) / 1e3, 4)}</td>" in report
    assert "<th>fatigue equivalent load (kN), w</th>" in report
    assert 'src="data:image/png;base64,' in report  # the figure, embedded
    cli_main([*argv, "--tables-only"])  # the folder's report as the campaign left it


@pytest.mark.parametrize(
    ("table", "expected"),
    [
        ("case,wave_hieght\na,1\n", "unknown column 'wave_hieght'"),
        # A motion table is read and checked before JAX too (not made into a motion).
        ("case,motion\na,two_points.csv\n", "case row 1: motion: "),
    ],
)
def test_a_bad_table_is_refused_before_jax_is_imported(files, tmp_path, table, expected):
    (tmp_path / "two_points.csv").write_text("0 1 2 3 4 5 6\n1 1 2 3 4 5 6\n")
    (tmp_path / "bad.csv").write_text(table)
    code = (
        "import sys; from jaxcable._cli import main; "
        f"status = main(['campaign', {str(files / 'scene.toml')!r}, {str(tmp_path / 'bad.csv')!r}, '--out', "
        f"{str(tmp_path / 'never')!r}]); print(status, 'jax' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["2", "False"], done.stderr
    assert expected in done.stderr and ("motion" not in table or "expected 4 columns" in done.stderr)
    assert not (tmp_path / "never").exists()


@pytest.mark.parametrize(
    ("flags", "expected"),
    [
        (["--shard", "2/2"], "shard must be i/n with 0 ≤ i < n, got 2/2"),
        (["--shard", "half"], "--shard must be I/N"),
        (["--batch", "0"], "batch must be a positive number of cases"),
        (["--duration", "1", "--statistics-from", "1"], "leaves nothing of a 1 s run"),
        (["--processes", "2"], "--coordinator, --processes and --process-id go together"),
        (["--coordinator", "here", "--processes", "2", "--process-id", "0"], "--coordinator must be HOST:PORT"),
        (["--coordinator", "here:1", "--processes", "2", "--process-id", "2"], "--process-id must be from 0"),
    ],
)
def test_bad_flags_are_refused(files, capsys, flags, expected):
    argv = ["campaign", str(files / "scene.toml"), str(files / "cases.csv"), "--out", str(files / "x"), *flags]
    assert cli_main(argv) == 2
    assert expected in capsys.readouterr().err


@pytest.mark.slow
def test_two_processes_give_what_one_gives(files, tmp_path):
    """Two local processes of JAX's multi-controller runtime run the campaign as one,
    its batch split across both processes' devices: the same results as one process."""
    # Two cases of one structure: one sweep.
    (tmp_path / "cases.csv").write_text("\n".join(CASES.splitlines()[:3]) + "\n")
    scene, cases = jc.read_scene(files / "scene.toml"), read_cases(tmp_path / "cases.csv")
    one = run_campaign(scene, cases, tmp_path / "one", table_folder=tmp_path)
    with socket.socket() as free:
        free.bind(("localhost", 0))
        port = free.getsockname()[1]
    command = [sys.executable, "-m", "jaxcable", "campaign", str(files / "scene.toml"), str(tmp_path / "cases.csv")]
    command += ["--out", str(tmp_path / "two"), "--coordinator", f"localhost:{port}", "--processes", "2"]
    started = [
        subprocess.Popen(
            [*command, "--process-id", str(i), "--no-progress"],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        for i in range(2)
    ]
    outputs = [process.communicate(timeout=900)[0] for process in started]
    assert [process.returncode for process in started] == [0, 0], outputs
    assert "2 case(s) run, 0 failed" in outputs[0]
    for case in cases:
        with xr.open_dataset(tmp_path / "two" / "cases" / f"{case.name}.nc") as two:
            with xr.open_dataset(one.folder / "cases" / f"{case.name}.nc") as alone:
                np.testing.assert_allclose(two["tension"].values, alone["tension"].values, rtol=1e-10, atol=1e-6)
