"""The assessment report and summary (python/hapsim/assessment_report.py) from fixture sessions
written here to the contract of `hapsim assess` (docs/assessment-report.md): every landmark and
tissue on the page, images embedded, limits drawn, a learning curve over the sessions, and bad
input as one line with exit 2. Needs matplotlib, not the compiled module."""

import base64
import copy
import csv
import html
import json
import math
import pathlib
import re
import struct
import subprocess
import sys

import pytest

SCRIPT = pathlib.Path(__file__).resolve().parents[1] / "hapsim" / "assessment_report.py"

LANDMARKS = ("patella apex", "tibial tuberosity", 'medial joint line <"JL"> & co')
TISSUES = ("patella", "tibia", "vastus_medialis")
RATE_HZ = 100
DURATION_S = 20.0


def _pulse(t, centre_s, width_s, peak_n):
    return peak_n * math.exp(-0.5 * ((t - centre_s) / width_s) ** 2)


def make_session(directory, *, variant=0, teleop=None, picture=True):
    """A palpation session of 20 s sampled at 100 Hz: the patella apex found at 3.2 s, the
    tibial tuberosity at 9.1 s, the medial joint line missed (touched lightly), and the vastus
    medialis pressed to 9.3 N against its 8 N limit from 5.0 s to 5.25 s. `variant` shifts the
    numbers so sessions differ. Returns the assessment (as written)."""
    directory = pathlib.Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    breach_peak_n = 9.3 - 0.9 * variant
    rows = []
    for i in range(int(DURATION_S * RATE_HZ)):
        t = i / RATE_HZ
        patella = _pulse(t, 3.0, 0.35, 2.6)
        tibia = _pulse(t, 9.0, 0.4, 3.1)
        vm = _pulse(t, 5.12, 0.18, breach_peak_n) + _pulse(t, 14.0, 0.5, 0.6)
        rows.append([t, patella + tibia + vm, patella, tibia, vm])
    columns = ["t_s", "total_force_n", *TISSUES]
    with open(directory / "forces.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for r in rows:
            w.writerow([f"{v:.6g}" for v in r])
    breached = breach_peak_n > 8.0
    breaches = ([{"tissue": "vastus_medialis", "start_s": 5.0, "duration_s": 0.25,
                  "peak_force_n": breach_peak_n, "excess_n": breach_peak_n - 8.0,
                  "point_m": [0.03, -0.01, 0.05]}] if breached else [])
    landmark = dict(point_m=[0.0, 0.05, 0.02], radius_m=0.01, required_force_n=2.0,
                    required_dwell_s=0.3)
    a = {
        "schema": "hapsim.assessment/1",
        "recording": f"session-{variant + 1}.rec",
        "scene": "scenes/knee_paper.json",
        "scene_name": "knee palpation (Visible Human knee)",
        "kind": "palpation",
        "duration_s": DURATION_S - 2.0 * variant,
        "time_limit_s": 60.0,
        "over_time": False,
        "path_length_m": 0.412,
        "mean_force_n": 1.21,
        "peak_force_n": max(r[1] for r in rows),
        "landmarks": [
            dict(landmark, name=LANDMARKS[0], segment="patella", found=True, found_at_s=3.2,
                 force_at_found_n=2.4, dwell_s=0.8, contact_s=1.1, mean_force_n=2.1,
                 peak_force_n=2.6),
            dict(landmark, name=LANDMARKS[1], segment="tibia", found=True, found_at_s=9.1,
                 force_at_found_n=2.9, dwell_s=0.9, contact_s=1.4, mean_force_n=2.3,
                 peak_force_n=3.1),
            dict(landmark, name=LANDMARKS[2], segment="vastus_medialis", found=variant >= 2,
                 found_at_s=14.2 if variant >= 2 else None,
                 force_at_found_n=2.1 if variant >= 2 else None, dwell_s=0.1, contact_s=0.6,
                 mean_force_n=0.5, peak_force_n=0.6),
        ],
        "limits": [
            {"tissue": "vastus_medialis", "max_force_n": 8.0, "breaches": len(breaches),
             "breach_duration_s": 0.25 if breached else 0.0,
             "worst_excess_n": breach_peak_n - 8.0 if breached else 0.0,
             "worst_at_s": 5.12 if breached else None, "worst_point_m": [0.03, -0.01, 0.05]},
            {"tissue": "patella", "max_force_n": 15.0, "breaches": 0, "breach_duration_s": 0.0,
             "worst_excess_n": 0.0, "worst_at_s": None, "worst_point_m": None},
        ],
        "breaches": breaches,
        "teleop": teleop,
        "score": {"value": 62.5 + 12.0 * variant, "max": 100.0,
                  "formula": "100 x (landmarks found / landmarks) - 10 per breach - 1 per 10 s "
                             "over half the time limit, floored at 0.",
                  "terms": {"landmarks": 66.7 + 16.6 * variant,
                            "breaches": -10.0 * len(breaches), "time": 0.0}},
        "forces": {"file": "forces.csv", "columns": columns},
        "picture": "picture.png" if picture else None,
    }
    if picture:
        _write_picture(directory / "picture.png")
    (directory / "assessment.json").write_text(json.dumps(a, indent=2))
    return a


def _write_picture(path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(12.8, 7.2), dpi=100)
    fig.patch.set_facecolor("#20252b")
    fig.savefig(path, dpi=100)
    plt.close(fig)


def run_script(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True,
                          text=True, check=False)


def png_size(data: bytes):
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    return struct.unpack(">II", data[16:24])


def embedded_images(page: str):
    """The decoded PNGs of every <img>; fails on any image that is not a data URI."""
    srcs = re.findall(r"<img[^>]*\ssrc=\"([^\"]*)\"", page)
    out = []
    for src in srcs:
        assert src.startswith("data:image/png;base64,"), f"not embedded: {src[:60]}"
        out.append(base64.b64decode(src.split(",", 1)[1], validate=True))
    return out


# One report for the tests that only read it (each run of the script costs seconds: CI time).
@pytest.fixture(scope="module")
def report(tmp_path_factory):
    d = tmp_path_factory.mktemp("report") / "session-01"
    a = make_session(d)
    r = run_script("report", d)
    assert r.returncode == 0, r.stderr
    return d, a, (d / "index.html").read_text(encoding="utf-8")


def test_report_names_every_landmark_with_its_state(report):
    _, a, page = report
    for lm in a["landmarks"]:
        name = html.escape(lm["name"], quote=True)
        row_start = page.find(f'<tr data-landmark="{name}"')
        m = re.match(r'<tr data-landmark="([^"]*)" data-state="(\w+)">', page[row_start:])
        assert m and m.group(1) == name and f"<b>{name}</b>" in page, lm["name"]
        assert m.group(2) == ("found" if lm["found"] else "missed"), lm["name"]
    # The one name with markup in it is escaped, never raw.
    assert '<"JL">' not in page and "&lt;&quot;JL&quot;&gt; &amp; co" in page


def test_report_names_every_tissue_and_the_breach(report):
    d, a, page = report
    for tissue in TISSUES:
        assert tissue.replace("_", " ") in page, tissue
        assert (d / f"force_{tissue}.png").exists(), tissue
    assert 'data-tissue="vastus_medialis"' in page
    breached = re.search(r'<tr class="breached" data-tissue="vastus_medialis">.*?</tr>', page)
    assert breached and "1 breach<" in breached.group(0) and "8.0&nbsp;N" in breached.group(0)
    assert re.search(r'<tr class="" data-tissue="patella">.*?within limit', page)
    assert "5.00&nbsp;s" in page  # the breach's start
    assert ">62.5<" in page  # the score


def test_report_is_self_contained(report):
    d, _, page = report
    images = embedded_images(page)
    # picture + total force + one plot per tissue, each a PNG.
    assert len(images) == 2 + len(TISSUES)
    assert png_size(images[0]) == (1280, 720)
    for img in images[1:]:
        w, h = png_size(img)
        assert w >= 800 and h >= 250
    for external in ("<script", "<link", "@import", "url(", "http://", "https://"):
        assert external not in page, external


def _pixels_near(path, rgb_hex, tol=0.15):
    import matplotlib.image as mpimg
    import numpy as np

    img = mpimg.imread(path)[..., :3]
    target = np.array([int(rgb_hex[i:i + 2], 16) / 255.0 for i in (1, 3, 5)])
    return int((np.abs(img - target).max(axis=2) < tol).sum())


def test_limit_and_finds_are_drawn_only_where_they_belong(report):
    d, _, _ = report
    # The vastus medialis has a limit (dashed red line, red label, shaded breach); the tibia has
    # none and no breach, so no pure limit-red pixel at all; both have their finds in green.
    assert _pixels_near(d / "force_vastus_medialis.png", "#d62728") > 600
    assert _pixels_near(d / "force_patella.png", "#d62728") > 600  # a limit, no breach
    assert _pixels_near(d / "force_tibia.png", "#d62728") == 0
    assert _pixels_near(d / "force_tibia.png", "#2ca02c") > 100
    assert _pixels_near(d / "force_vastus_medialis.png", "#2ca02c") == 0  # its landmark is missed


def test_teleop_block_only_when_teleop_is_set(tmp_path):
    make_session(tmp_path / "a", teleop={"time_to_grasp_s": 3.2, "drops": 1,
                                         "placement_error_m": 0.004, "peak_grasp_force_n": 6.5,
                                         "collisions": 0, "placed": True})
    make_session(tmp_path / "b", picture=False)
    for d in ("a", "b"):
        assert run_script("report", tmp_path / d).returncode == 0
    with_teleop = (tmp_path / "a" / "index.html").read_text()
    without = (tmp_path / "b" / "index.html").read_text()
    assert 'id="teleop"' in with_teleop and "4.0&nbsp;mm" in with_teleop
    assert "Time to grasp" in with_teleop and "3.20&nbsp;s" in with_teleop
    assert 'id="teleop"' not in without
    assert "No picture was drawn" in without and len(embedded_images(without)) == 1 + len(TISSUES)


def test_summary_over_three_sessions(tmp_path):
    jsons = []
    for i in range(3):
        d = tmp_path / f"session-{i + 1:02d}"
        make_session(d, variant=i)
        # The summary links each session's page and reads only its assessment.json: a page
        # stands in for the report (the report itself is tested above; a run costs seconds).
        (d / "index.html").write_text("<html></html>", encoding="utf-8")
        jsons.append(d / "assessment.json")
    r = run_script("summary", tmp_path, *jsons)
    assert r.returncode == 0, r.stderr
    page = (tmp_path / "index.html").read_text()
    curve = (tmp_path / "learning_curve.png").read_bytes()
    assert png_size(curve) == (900, 750)
    assert curve in embedded_images(page)
    for i in range(3):
        row = re.search(rf'<tr data-session="{i + 1}">.*?</tr>', page)
        assert row, i
        assert f"session-{i + 1}.rec" in row.group(0)
        assert f'href="session-{i + 1:02d}/index.html"' in row.group(0)
    # errors = missed landmarks + breaches: 1+1, 1+0 (9.3-0.9 = 8.4 still breaches: 1+1), 0+0
    errors = [int(e) for e in re.findall(r'data-errors="(\d+)"', page)]
    assert errors == [2, 2, 0]
    # The errors panel stacks missed landmarks (grey) and breaches (red): two of each here.
    bar_px = _pixels_near(tmp_path / "learning_curve.png", "#7f7f7f", tol=0.02)
    assert bar_px > 2000
    assert abs(_pixels_near(tmp_path / "learning_curve.png", "#d62728", tol=0.02) - bar_px) \
        < 0.35 * bar_px


def test_summary_plots_any_number_of_sessions_to_the_same_size(tmp_path):
    d = tmp_path / "one"
    make_session(d, picture=False)
    r = run_script("summary", tmp_path / "out", d / "assessment.json")
    assert r.returncode == 0, r.stderr
    assert png_size((tmp_path / "out" / "learning_curve.png").read_bytes()) == (900, 750)
    # The report was not made: the row says so instead of a dead link.
    assert "no report" in (tmp_path / "out" / "index.html").read_text()


def _break(tmp_path, how):
    d = tmp_path / "s"
    a = make_session(d, picture=False)
    bad = copy.deepcopy(a)
    if how == "schema":
        bad["schema"] = "hapsim.assessment/0"
    elif how == "landmark name":
        del bad["landmarks"][1]["name"]
    elif how == "nan":
        bad["duration_s"] = float("nan")
    elif how == "columns":
        bad["forces"]["columns"] = ["total_force_n", "t_s"]
    elif how == "no tissue column":
        bad["limits"][0]["tissue"] = "gastrocnemius"
    if how in ("schema", "landmark name", "nan", "columns", "no tissue column"):
        (d / "assessment.json").write_text(json.dumps(bad))
    elif how == "truncated json":
        (d / "assessment.json").write_text(json.dumps(a)[:200])
    elif how == "no json":
        (d / "assessment.json").unlink()
    elif how == "no csv":
        (d / "forces.csv").unlink()
    elif how == "csv text":
        lines = (d / "forces.csv").read_text().splitlines()
        fields = lines[17].split(",")
        fields[2] = "abc"  # the patella's force
        lines[17] = ",".join(fields)
        (d / "forces.csv").write_text("\n".join(lines) + "\n")
    elif how == "csv header":
        lines = (d / "forces.csv").read_text().splitlines()
        lines[0] = "t_s,total_force_n,patella,tibia,femur"
        (d / "forces.csv").write_text("\n".join(lines) + "\n")
    elif how == "csv fields":
        with open(d / "forces.csv", "a") as f:
            f.write("20.0,1.0\n")
    elif how == "not a png":
        bad["picture"] = "picture.png"
        (d / "picture.png").write_text("not an image")
        (d / "assessment.json").write_text(json.dumps(bad))
    return d


@pytest.mark.parametrize("how, names, says", [
    ("no json", "assessment.json", "no such file"),
    ("truncated json", "assessment.json", "not JSON"),
    ("schema", "assessment.json", "hapsim.assessment/1"),
    ("landmark name", "assessment.json", "landmarks[1].name is missing"),
    ("nan", "assessment.json", "duration_s"),
    ("columns", "assessment.json", "forces.columns"),
    ("no tissue column", "assessment.json", 'no column for limits[0].tissue "gastrocnemius"'),
    ("no csv", "forces.csv", "no such file"),
    ("csv text", "forces.csv", 'line 18: patella is "abc"'),
    ("csv header", "forces.csv", "header"),
    ("csv fields", "forces.csv", "2 fields"),
    ("not a png", "picture.png", "not a PNG"),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, how, names, says):
    d = _break(tmp_path, how)
    r = run_script("report", d)
    assert r.returncode == 2, (how, r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert names in lines[0] and says in lines[0], lines[0]
    assert "Traceback" not in r.stderr
    assert not (d / "index.html").exists()


def test_summary_with_a_missing_session_is_one_line_and_exit_2(tmp_path):
    make_session(tmp_path / "a", picture=False)
    r = run_script("summary", tmp_path / "out", tmp_path / "a" / "assessment.json",
                   tmp_path / "b" / "assessment.json")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert str(tmp_path / "b" / "assessment.json") in r.stderr
    assert not (tmp_path / "out" / "index.html").exists()


@pytest.mark.parametrize("args", [[], ["report"], ["bogus", "x"], ["summary", "out"]])
def test_bad_usage_is_one_line_and_exit_2(args):
    r = run_script(*args)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "usage:" in r.stderr


def test_a_named_picture_that_is_missing_is_said_once_and_the_report_is_made(tmp_path):
    d = tmp_path / "s"
    make_session(d)
    (d / "picture.png").unlink()
    r = run_script("report", d)
    assert r.returncode == 0, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "picture.png" in lines[0] and "missing" in lines[0], r.stderr
    page = (d / "index.html").read_text()
    assert "picture.png is missing" in page and len(embedded_images(page)) == 1 + len(TISSUES)
