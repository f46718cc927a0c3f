#!/usr/bin/python3
"""The training report of `hapsim assess` (docs/assessment-report.md).

    assessment_report.py report DIR
        reads DIR/assessment.json (schema "hapsim.assessment/1"), DIR/forces.csv and
        DIR/picture.png (when the assessment names one) and writes DIR/index.html with its plots
        (DIR/force_total.png, DIR/force_<tissue>.png).
    assessment_report.py summary OUT_DIR A.json B.json ...
        reads one assessment per session, in session order, and writes OUT_DIR/index.html (a
        learning curve: score, errors and time per session, and a table linking each session's
        report) and OUT_DIR/learning_curve.png.

The pages are self-contained (inline CSS, images as base64 data URIs, no script, no external
font) so they open offline and can be mailed. Pure Python and matplotlib (Agg): the compiled
`_hapsim` module is not needed. Bad input is one line on stderr naming the file and what is
wrong, exit 2.
"""

from __future__ import annotations

import base64
import csv
import datetime
import html
import json
import math
import os
import re
import sys

SCHEMA = "hapsim.assessment/1"
FOUND_COLOUR = "#2ca02c"
MISSED_COLOUR = "#7f7f7f"
BREACH_COLOUR = "#d62728"
FORCE_COLOUR = "#1f4e79"
LEARNING_CURVE_SIZE_PX = (900, 750)  # width, height (the tests check it)
_DPI = 100


class InputError(Exception):
    """Bad input: its message is the one line the user reads."""


def _fail(message: str) -> None:
    print(f"assessment_report.py: {message}", file=sys.stderr)
    sys.exit(2)


def _ensure_matplotlib() -> None:
    """A pyenv `python3` first on the PATH usually has no matplotlib (docs/python.md): then the
    script runs again under Debian's /usr/bin/python3, where scripts/setup.sh installs it (the
    same pages; no extra line, so bad input stays one line). Checked before anything is read,
    imported only when plotting."""
    import importlib.util

    if importlib.util.find_spec("matplotlib") is not None:
        return
    debian = "/usr/bin/python3"
    if (os.environ.get("HAPSIM_REPORT_REEXEC") != "1" and os.access(debian, os.X_OK)
            and os.path.realpath(sys.executable) != os.path.realpath(debian)):
        os.environ["HAPSIM_REPORT_REEXEC"] = "1"
        os.execv(debian, [debian, os.path.abspath(__file__), *sys.argv[1:]])
    _fail(f"matplotlib is not installed for {sys.executable} (scripts/setup.sh installs "
          "python3-matplotlib for /usr/bin/python3)")


def _import_matplotlib():
    """pyplot on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


# ---------------------------------------------------------------------------------------------
# Reading and checking the input


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


class _Checker:
    """Checks one assessment's fields, naming the file and the field in its message."""

    def __init__(self, path: str):
        self.path = path

    def fail(self, where: str, what: str):
        raise InputError(f"{self.path}: {where} {what}")

    def number(self, obj: dict, key: str, where: str, *, optional=False, nullable=False):
        if key not in obj:
            if optional:
                return None
            self.fail(f"{where}{key}", "is missing")
        v = obj[key]
        if v is None and (nullable or optional):
            return None
        if not _is_number(v):
            self.fail(f"{where}{key}", f"is {json.dumps(v)[:40]}, expected a finite number")
        return float(v)

    def string(self, obj: dict, key: str, where: str, *, optional=False, nullable=False):
        if key not in obj:
            if optional:
                return None
            self.fail(f"{where}{key}", "is missing")
        v = obj[key]
        if v is None and (nullable or optional):
            return None
        if not isinstance(v, str):
            self.fail(f"{where}{key}", f"is {json.dumps(v)[:40]}, expected a string")
        return v

    def boolean(self, obj: dict, key: str, where: str, *, optional=False):
        if key not in obj and optional:
            return None
        if key not in obj:
            self.fail(f"{where}{key}", "is missing")
        v = obj[key]
        if v is None and optional:
            return None
        if not isinstance(v, bool):
            self.fail(f"{where}{key}", f"is {json.dumps(v)[:40]}, expected true or false")
        return v

    def obj_list(self, obj: dict, key: str):
        if key not in obj:
            self.fail(key, "is missing")
        v = obj[key]
        if not isinstance(v, list) or not all(isinstance(e, dict) for e in v):
            self.fail(key, "is not a list of objects")
        return v


def load_assessment(path: str) -> dict:
    """The assessment at `path`, checked against schema hapsim.assessment/1 (numbers finite,
    nulls only where the schema allows them). Raises InputError."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{path}: cannot be read ({e})") from None
    try:
        a = json.loads(text, parse_constant=lambda c: float("nan"))
    except json.JSONDecodeError as e:
        raise InputError(f"{path}: line {e.lineno} column {e.colno}: not JSON ({e.msg})") from None
    c = _Checker(path)
    if not isinstance(a, dict):
        c.fail("the top level", "is not a JSON object")
    if a.get("schema") != SCHEMA:
        c.fail("schema", f"is {json.dumps(a.get('schema'))[:40]}, expected \"{SCHEMA}\"")
    for key in ("recording", "scene"):
        c.string(a, key, "")
    c.string(a, "scene_name", "", optional=True)
    c.string(a, "kind", "", optional=True)
    c.number(a, "duration_s", "")
    if a["duration_s"] < 0:
        c.fail("duration_s", "is negative")
    c.number(a, "time_limit_s", "", optional=True)
    c.boolean(a, "over_time", "", optional=True)
    for key in ("path_length_m", "mean_force_n", "peak_force_n"):
        c.number(a, key, "", optional=True)

    for i, lm in enumerate(c.obj_list(a, "landmarks")):
        w = f"landmarks[{i}]."
        c.string(lm, "name", w)
        c.string(lm, "segment", w, optional=True)
        found = c.boolean(lm, "found", w)
        for key in ("required_force_n", "required_dwell_s", "dwell_s", "contact_s"):
            c.number(lm, key, w, optional=True)
        for key in ("found_at_s", "force_at_found_n", "mean_force_n", "peak_force_n", "radius_m"):
            c.number(lm, key, w, optional=True)
        if found and lm.get("found_at_s") is None:
            c.fail(f"{w}found_at_s", "is null but the landmark is found")
    for i, lim in enumerate(c.obj_list(a, "limits")):
        w = f"limits[{i}]."
        c.string(lim, "tissue", w)
        c.number(lim, "max_force_n", w)
        c.number(lim, "breaches", w, optional=True)
        for key in ("breach_duration_s", "worst_excess_n", "worst_at_s"):
            c.number(lim, key, w, optional=True)
    for i, b in enumerate(c.obj_list(a, "breaches")):
        w = f"breaches[{i}]."
        c.string(b, "tissue", w)
        c.number(b, "start_s", w)
        c.number(b, "duration_s", w)
        for key in ("peak_force_n", "excess_n"):
            c.number(b, key, w, optional=True)

    teleop = a.get("teleop")
    if teleop is not None and not isinstance(teleop, dict):
        c.fail("teleop", "is neither null nor an object")

    score = a.get("score")
    if not isinstance(score, dict):
        c.fail("score", "is missing or not an object")
    c.number(score, "value", "score.")
    c.number(score, "max", "score.")
    c.string(score, "formula", "score.", optional=True)
    terms = score.get("terms", {})
    if not isinstance(terms, dict) or not all(_is_number(v) for v in terms.values()):
        c.fail("score.terms", "is not an object of finite numbers")

    forces = a.get("forces")
    if not isinstance(forces, dict):
        c.fail("forces", "is missing or not an object")
    c.string(forces, "file", "forces.")
    cols = forces.get("columns")
    if (not isinstance(cols, list) or len(cols) < 2 or not all(isinstance(s, str) for s in cols)
            or cols[:2] != ["t_s", "total_force_n"]):
        c.fail("forces.columns", "is not a list of names starting \"t_s\", \"total_force_n\"")
    if len(set(cols)) != len(cols):
        c.fail("forces.columns", "names a column twice")
    # One column per tissue with a limit or a landmark on it (the contract), so no plot is missing.
    named = [(f"limits[{i}].tissue", lim["tissue"]) for i, lim in enumerate(a["limits"])]
    named += [(f"landmarks[{i}].segment", lm["segment"])
              for i, lm in enumerate(a["landmarks"]) if lm.get("segment")]
    for where, tissue in named:
        if tissue not in cols[2:]:
            c.fail("forces.columns", f"has no column for {where} \"{tissue[:40]}\"")
    c.string(a, "picture", "", optional=True)
    return a


def load_forces(path: str, columns: list[str]) -> dict[str, list[float]]:
    """forces.csv as one list per column; the header must be `columns`. Raises InputError."""
    try:
        with open(path, encoding="utf-8", newline="") as f:
            rows = list(csv.reader(f))
    except FileNotFoundError:
        raise InputError(f"{path}: no such file (assessment.json names it in forces.file)") \
            from None
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        raise InputError(f"{path}: cannot be read ({e})") from None
    if not rows:
        raise InputError(f"{path}: is empty (expected the header {','.join(columns)})")
    header = [h.strip() for h in rows[0]]
    if header != columns:
        raise InputError(f"{path}: line 1: the header is {','.join(header)[:80]}, assessment.json "
                         f"says {','.join(columns)[:80]}")
    data: dict[str, list[float]] = {c: [] for c in columns}
    previous_t = -math.inf
    for line, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) != len(columns):
            raise InputError(f"{path}: line {line}: {len(row)} fields, the header has "
                             f"{len(columns)}")
        for name, cell in zip(columns, row):
            try:
                v = float(cell)
            except ValueError:
                v = math.nan
            if not math.isfinite(v):
                raise InputError(f"{path}: line {line}: {name} is \"{cell.strip()[:20]}\", "
                                 "expected a finite number")
            data[name].append(v)
        t = data["t_s"][-1]
        if t < previous_t:
            raise InputError(f"{path}: line {line}: t_s {t:g} goes back in time "
                             f"(from {previous_t:g})")
        previous_t = t
    if not data["t_s"]:
        raise InputError(f"{path}: has a header but no rows")
    return data


def _read_png(path: str) -> bytes:
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise InputError(f"{path}: cannot be read ({e.strerror})") from None
    if not data.startswith(b"\x89PNG\r\n\x1a\n"):
        raise InputError(f"{path}: is not a PNG image")
    return data


# ---------------------------------------------------------------------------------------------
# Formatting


def _esc(v) -> str:
    return html.escape(str(v), quote=True)


def _num(v, digits=2, unit="") -> str:
    if v is None:
        return '<span class="na">—</span>'
    s = f"{v:.{digits}f}"
    return f"{s}&nbsp;{unit}" if unit else s


def _signed(v: float) -> str:
    return f"+{v:.1f}" if v > 0 else (f"−{-v:.1f}" if v < 0 else "0.0")


def _data_uri(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def _file_stem(tissue: str) -> str:
    return re.sub(r"[^A-Za-z0-9_-]", "_", tissue)


def _pretty(name: str) -> str:
    return name.replace("_", " ")


def _field_label_and_value(key: str, v) -> tuple[str, str]:
    """A teleop field by its unit suffix: `placement_error_m` → ("placement error", "4.0 mm")."""
    label = key
    for suffix in ("_s", "_m", "_n"):
        if key.endswith(suffix):
            label = key[: -len(suffix)]
    label = _pretty(label).capitalize()
    if isinstance(v, bool):
        return label, "yes" if v else "no"
    if v is None:
        return label, _num(None)
    if _is_number(v):
        if key.endswith("_m"):
            return label, _num(v * 1000.0, 1, "mm")
        if key.endswith("_s"):
            return label, _num(v, 2, "s")
        if key.endswith("_n"):
            return label, _num(v, 2, "N")
        return label, f"{v:g}" if isinstance(v, float) else str(v)
    return label, _esc(v)


# ---------------------------------------------------------------------------------------------
# Plots


def _style(plt):
    plt.rcParams.update({
        "font.family": "DejaVu Sans",
        "font.size": 10,
        "axes.spines.top": False,
        "axes.spines.right": False,
        "axes.edgecolor": "#555555",
        "axes.labelcolor": "#222222",
        "axes.grid": True,
        "grid.color": "#e3e3e3",
        "grid.linewidth": 0.8,
        "xtick.color": "#444444",
        "ytick.color": "#444444",
        "legend.frameon": False,
        "legend.fontsize": 9,
        "savefig.facecolor": "white",
    })


def _finds_on(assessment: dict, tissue: str | None) -> list[tuple[int, dict]]:
    """The found landmarks (1-based number as in the table) on `tissue` (None: all)."""
    return [(i + 1, lm) for i, lm in enumerate(assessment["landmarks"])
            if lm["found"] and (tissue is None or lm.get("segment") == tissue)]


def _force_plot(plt, path: str, t, force, *, duration_s: float, limit_n, breaches,
                finds, ylabel: str, height_in: float):
    """One force-over-time plot: the force, its limit as a labelled horizontal line, breach
    intervals shaded, each landmark's find marked with its number at the top."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from matplotlib.transforms import blended_transform_factory

    fig, ax = plt.subplots(figsize=(10.0, height_in), dpi=_DPI)
    t_end = max(duration_s, t[-1] if t else 0.0, 1e-3)
    peak = max(force) if force else 0.0
    # The curve and the limit below 3/4 of the height: the find markers sit above them.
    top = max(peak, limit_n or 0.0, 0.5) * 1.34
    handles = [Line2D([], [], color=FORCE_COLOUR, lw=1.4, label="force")]
    for b in breaches:
        ax.axvspan(b["start_s"], b["start_s"] + max(b["duration_s"], t_end * 0.002),
                   color=BREACH_COLOUR, alpha=0.16, lw=0)
    ax.plot(t, force, color=FORCE_COLOUR, lw=1.3, solid_joinstyle="round")
    if limit_n is not None:
        ax.axhline(limit_n, color=BREACH_COLOUR, lw=1.3, ls=(0, (6, 3)))
        ax.text(t_end, limit_n, f"limit {limit_n:.1f} N ", color=BREACH_COLOUR, fontsize=9,
                ha="right", va="bottom", fontweight="bold",
                bbox=dict(facecolor="white", edgecolor="none", pad=1.0, alpha=0.85))
        handles.append(Line2D([], [], color=BREACH_COLOUR, lw=1.3, ls=(0, (6, 3)), label="limit"))
    if breaches:
        handles.append(Patch(color=BREACH_COLOUR, alpha=0.3, label="over the limit"))
    # Landmark finds: a line and the landmark's number, staggered when two are close in time.
    trans = blended_transform_factory(ax.transData, ax.transAxes)
    last_x, level = -math.inf, 0
    for number, lm in sorted(finds, key=lambda f: f[1]["found_at_s"]):
        x = lm["found_at_s"]
        level = (level + 1) % 2 if x - last_x < 0.045 * t_end else 0
        last_x = x
        ax.axvline(x, color=FOUND_COLOUR, lw=1.0, ls=":")
        ax.text(x, 0.93 - 0.1 * level, str(number), transform=trans, ha="center", va="center",
                color="white", fontsize=8, fontweight="bold",
                bbox=dict(boxstyle="circle,pad=0.25", facecolor=FOUND_COLOUR, edgecolor="none"))
    if finds:
        handles.append(Line2D([], [], color=FOUND_COLOUR, lw=0, marker="o", markersize=7,
                              label="landmark found (its number)"))
    ax.set_xlim(0.0, t_end)
    ax.set_ylim(0.0, top)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(ylabel)
    ax.legend(handles=handles, loc="lower right", bbox_to_anchor=(1.0, 1.0), ncol=len(handles),
              borderaxespad=0.2, handlelength=1.8)
    # Fixed margins (inches), not tight_layout: every plot's time axis lines up on the page.
    w_in, h_in = fig.get_size_inches()
    fig.subplots_adjust(left=0.85 / w_in, right=1.0 - 0.2 / w_in, bottom=0.55 / h_in,
                        top=1.0 - 0.4 / h_in)
    fig.savefig(path, dpi=_DPI)
    plt.close(fig)


def _learning_curve(plt, path: str, sessions: list[dict]):
    from matplotlib.patches import Patch
    from matplotlib.ticker import FixedLocator, MaxNLocator

    n = len(sessions)
    x = list(range(1, n + 1))
    w, h = LEARNING_CURVE_SIZE_PX
    fig, (ax_score, ax_err, ax_time) = plt.subplots(3, 1, figsize=(w / _DPI, h / _DPI), dpi=_DPI,
                                                    sharex=True)
    score = [s["score"] for s in sessions]
    score_max = max(s["score_max"] for s in sessions)
    ax_score.plot(x, score, color=FORCE_COLOUR, lw=1.8, marker="o", markersize=6)
    for xi, v in zip(x, score):
        ax_score.annotate(f"{v:.1f}", (xi, v), textcoords="offset points", xytext=(0, 7),
                          ha="center", fontsize=9, color=FORCE_COLOUR)
    ax_score.set_ylim(min(0.0, min(score) * 1.1), score_max * 1.15)
    ax_score.set_ylabel(f"score (of {score_max:g})")

    missed = [s["missed"] for s in sessions]
    breaches = [s["breaches"] for s in sessions]
    ax_err.bar(x, missed, width=0.55, color=MISSED_COLOUR, label="missed landmarks")
    ax_err.bar(x, breaches, width=0.55, bottom=missed, color=BREACH_COLOUR, label="breaches")
    for xi, m, b in zip(x, missed, breaches):  # the total, so a session without errors shows 0
        ax_err.annotate(str(m + b), (xi, m + b), textcoords="offset points", xytext=(0, 4),
                        ha="center", fontsize=9, color="#333333")
    top = max([m + b for m, b in zip(missed, breaches)] + [1])
    ax_err.set_ylim(0, top * 1.5)
    ax_err.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax_err.set_ylabel("errors")
    ax_err.legend(handles=[Patch(color=MISSED_COLOUR, label="missed landmarks"),
                           Patch(color=BREACH_COLOUR, label="breaches")],
                  loc="upper right", ncol=2)

    t = [s["duration_s"] for s in sessions]
    ax_time.plot(x, t, color="#444444", lw=1.8, marker="s", markersize=5)
    limits = {s["time_limit_s"] for s in sessions}
    t_top = max(t + [1e-3])
    if len(limits) == 1 and None not in limits:
        limit = limits.pop()
        ax_time.axhline(limit, color=BREACH_COLOUR, lw=1.2, ls=(0, (6, 3)))
        ax_time.text(n + 0.45, limit, f"time limit {limit:g} s", color=BREACH_COLOUR, fontsize=9,
                     ha="right", va="bottom",
                     bbox=dict(facecolor="white", edgecolor="none", pad=1.0, alpha=0.85))
        t_top = max(t_top, limit)
    ax_time.set_ylim(0.0, t_top * 1.2)
    ax_time.set_ylabel("time per session (s)")
    for ax in (ax_score, ax_err, ax_time):
        ax.grid(axis="x", visible=False)
    ax_time.set_xlabel("session")
    ax_time.xaxis.set_major_locator(FixedLocator(x) if n <= 20 else MaxNLocator(integer=True))
    ax_time.set_xlim(0.5, n + 0.5)
    fig.align_ylabels()
    fig.tight_layout(pad=0.8)
    fig.savefig(path, dpi=_DPI)
    plt.close(fig)


# ---------------------------------------------------------------------------------------------
# HTML

_CSS = """
:root { --ink:#1d2733; --muted:#5f6b7a; --rule:#dde3ea; --panel:#f5f7fa; --accent:#1f4e79;
        --found:#2ca02c; --missed:#7f7f7f; --breach:#d62728; }
* { box-sizing:border-box; }
body { margin:0; background:#eef1f5; color:var(--ink);
       font:15px/1.5 "Segoe UI","Helvetica Neue","DejaVu Sans",Arial,sans-serif; }
.page { max-width:1120px; margin:24px auto; background:#fff; padding:36px 44px 44px;
        box-shadow:0 1px 4px rgba(0,0,0,.08); border-radius:4px; }
header { display:flex; justify-content:space-between; gap:32px; align-items:flex-start;
         border-bottom:3px solid var(--accent); padding-bottom:20px; }
.eyebrow { text-transform:uppercase; letter-spacing:.08em; font-size:12px; color:var(--muted);
           font-weight:600; }
h1 { font-size:28px; line-height:1.2; margin:4px 0 10px; font-weight:650; }
h2 { font-size:19px; margin:36px 0 12px; padding-bottom:6px; border-bottom:1px solid var(--rule);
     font-weight:650; }
h3 { font-size:15px; margin:22px 0 6px; font-weight:650; }
.meta { color:var(--muted); font-size:13.5px; margin:0; }
.meta b { color:var(--ink); font-weight:600; }
.score { text-align:right; min-width:230px; }
.score .value { font-size:64px; line-height:1; font-weight:700; color:var(--accent);
                font-variant-numeric:tabular-nums; }
.score .max { font-size:22px; color:var(--muted); font-weight:500; }
.bar { height:8px; background:var(--rule); border-radius:4px; margin:10px 0 8px; overflow:hidden; }
.bar span { display:block; height:100%; background:var(--accent); }
.terms { font-size:13.5px; color:var(--muted); border-collapse:collapse; margin-left:auto; }
.terms td { padding:1px 0 1px 14px; border:0; }
.terms td.v { text-align:right; font-variant-numeric:tabular-nums; color:var(--ink);
              font-weight:600; }
.formula { background:var(--panel); border-left:3px solid var(--accent); padding:10px 14px;
           font-size:13.5px; color:#34404d; margin:16px 0 0; }
.kpis { display:grid; grid-template-columns:repeat(auto-fit,minmax(150px,1fr)); gap:12px;
        margin:22px 0 0; }
.kpi { background:var(--panel); border-radius:4px; padding:10px 14px; }
.kpi .k { font-size:12px; text-transform:uppercase; letter-spacing:.06em; color:var(--muted); }
.kpi .v { font-size:22px; font-weight:650; font-variant-numeric:tabular-nums; }
.kpi.alert .v { color:var(--breach); }
.kpi.good .v { color:var(--found); }
table.data { width:100%; border-collapse:collapse; font-size:13.5px;
             font-variant-numeric:tabular-nums; }
table.data th { text-align:left; font-weight:600; color:var(--muted); font-size:12px;
                text-transform:uppercase; letter-spacing:.04em; border-bottom:2px solid var(--rule);
                padding:6px 8px; vertical-align:bottom; }
table.data td { border-bottom:1px solid var(--rule); padding:7px 8px; vertical-align:top; }
table.data td.n, table.data th.n { text-align:right; }
table.data td.n { white-space:nowrap; }
table.data td.name { min-width:190px; }
table.data tr.breached td { background:#fdf0f0; }
.sub { color:var(--muted); font-size:12px; }
.pill { display:inline-block; padding:1px 9px; border-radius:10px; font-size:12px; font-weight:600;
        color:#fff; white-space:nowrap; }
.pill.found { background:var(--found); } .pill.missed { background:var(--missed); }
.pill.breach { background:var(--breach); } .pill.ok { background:#e7f4e7; color:#226f22; }
.num { display:inline-block; width:20px; height:20px; border-radius:50%; text-align:center;
       line-height:20px; font-size:11px; font-weight:700; color:#fff; background:var(--missed); }
.num.found { background:var(--found); }
figure { margin:0; }
figure img { width:100%; height:auto; display:block; border:1px solid var(--rule);
             border-radius:3px; }
figcaption { font-size:12.5px; color:var(--muted); margin-top:6px; }
.legend { display:flex; gap:22px; flex-wrap:wrap; font-size:13px; margin-top:8px; color:#34404d; }
.legend i { display:inline-block; width:12px; height:12px; border-radius:50%; margin-right:6px;
            vertical-align:-1px; }
.note { color:var(--muted); font-style:italic; font-size:13.5px; }
.flag { color:var(--breach); font-weight:600; }
footer { margin-top:40px; padding-top:12px; border-top:1px solid var(--rule); font-size:12px;
         color:var(--muted); }
a { color:var(--accent); }
@media print {
  body { background:#fff; font-size:12px; -webkit-print-color-adjust:exact; print-color-adjust:exact; }
  .page { box-shadow:none; margin:0; max-width:none; padding:0; }
  h2, h3 { break-after:avoid-page; }
  header, .kpis, table.data { break-inside:avoid-page; }
  figure, table.data tr { break-inside:avoid-page; }
  a { color:inherit; text-decoration:none; }
}
"""


def _page(title: str, body: str) -> str:
    return ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<title>{_esc(title)}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n"
            f"<div class=\"page\">\n{body}\n</div>\n</body>\n</html>\n")


def _now_utc() -> str:
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


def _kpi(label: str, value: str, cls: str = "") -> str:
    return (f'<div class="kpi {cls}"><div class="k">{_esc(label)}</div>'
            f'<div class="v">{value}</div></div>')


def _score_block(a: dict) -> str:
    s = a["score"]
    frac = 0.0 if s["max"] <= 0 else min(max(s["value"] / s["max"], 0.0), 1.0)
    terms = "".join(f"<tr><td>{_esc(_pretty(k))}</td><td class=\"v\">{_signed(v)}</td></tr>"
                    for k, v in s.get("terms", {}).items())
    return (f'<div class="score"><div class="eyebrow">Score</div>'
            f'<div class="value">{s["value"]:.1f}<span class="max"> / {s["max"]:g}</span></div>'
            f'<div class="bar"><span style="width:{frac * 100:.1f}%"></span></div>'
            f'<table class="terms">{terms}</table></div>')


def _landmark_table(a: dict) -> str:
    if not a["landmarks"]:
        return '<p class="note">This scene names no landmarks.</p>'
    rows = []
    for i, lm in enumerate(a["landmarks"], start=1):
        state = "found" if lm["found"] else "missed"
        req = ""
        if lm.get("required_force_n") is not None:
            req = f"≥&nbsp;{lm['required_force_n']:.1f}&nbsp;N"
            if lm.get("required_dwell_s") is not None:
                req += f" for {lm['required_dwell_s']:.1f}&nbsp;s"
        where = _esc(_pretty(lm["segment"])) if lm.get("segment") else ""
        if lm.get("radius_m") is not None:
            where += f", within {lm['radius_m'] * 1000:.0f}&nbsp;mm"
        rows.append(
            f'<tr data-landmark="{_esc(lm["name"])}" data-state="{state}">'
            f'<td><span class="num {state}">{i}</span></td>'
            f'<td class="name"><b>{_esc(lm["name"])}</b><br><span class="sub">{where}</span></td>'
            f'<td><span class="pill {state}">{state}</span></td>'
            f'<td class="n">{_num(lm.get("found_at_s"), 2, "s")}</td>'
            f'<td class="n">{_num(lm.get("force_at_found_n"), 2, "N")}</td>'
            f'<td class="n">{req or _num(None)}</td>'
            f'<td class="n">{_num(lm.get("dwell_s"), 2, "s")}</td>'
            f'<td class="n">{_num(lm.get("contact_s"), 2, "s")}</td>'
            f'<td class="n">{_num(lm.get("mean_force_n"), 2, "N")}</td>'
            f'<td class="n">{_num(lm.get("peak_force_n"), 2, "N")}</td></tr>')
    return ('<table class="data"><thead><tr><th>#</th><th>Landmark</th><th>Result</th>'
            '<th class="n">Found at</th><th class="n">Force at find</th><th class="n">Required</th>'
            '<th class="n">Longest dwell</th><th class="n">Contact time</th>'
            '<th class="n">Mean force</th><th class="n">Peak force</th></tr></thead><tbody>'
            + "".join(rows) + "</tbody></table>")


def _limits_tables(a: dict) -> str:
    if not a["limits"]:
        return '<p class="note">This scene sets no force limits.</p>'
    rows = []
    for lim in a["limits"]:
        count = sum(1 for b in a["breaches"] if b["tissue"] == lim["tissue"])
        if lim.get("breaches") is not None:
            count = int(lim["breaches"])
        state = (f'<span class="pill breach">{count} breach{"es" if count != 1 else ""}</span>'
                 if count else '<span class="pill ok">within limit</span>')
        rows.append(
            f'<tr class="{"breached" if count else ""}" data-tissue="{_esc(lim["tissue"])}">'
            f'<td><b>{_esc(_pretty(lim["tissue"]))}</b></td>'
            f'<td class="n">{_num(lim["max_force_n"], 1, "N")}</td>'
            f'<td>{state}</td><td class="n">{_num(lim.get("breach_duration_s"), 2, "s")}</td>'
            f'<td class="n">{_num(lim.get("worst_excess_n") if count else None, 2, "N")}</td>'
            f'<td class="n">{_num(lim.get("worst_at_s") if count else None, 2, "s")}</td></tr>')
    out = ('<table class="data"><thead><tr><th>Tissue</th><th class="n">Limit</th><th>Result</th>'
           '<th class="n">Time over limit</th><th class="n">Worst excess</th>'
           '<th class="n">Worst at</th></tr></thead><tbody>' + "".join(rows) + "</tbody></table>")
    if a["breaches"]:
        brows = "".join(
            f'<tr class="breached"><td>{i}</td><td>{_esc(_pretty(b["tissue"]))}</td>'
            f'<td class="n">{_num(b["start_s"], 2, "s")}</td>'
            f'<td class="n">{_num(b["duration_s"], 2, "s")}</td>'
            f'<td class="n">{_num(b.get("peak_force_n"), 2, "N")}</td>'
            f'<td class="n">{_num(b.get("excess_n"), 2, "N")}</td></tr>'
            for i, b in enumerate(sorted(a["breaches"], key=lambda b: b["start_s"]), start=1))
        out += ('<h3>Each breach</h3><table class="data"><thead><tr><th>#</th><th>Tissue</th>'
                '<th class="n">Start</th><th class="n">Duration</th><th class="n">Peak force</th>'
                '<th class="n">Excess</th></tr></thead><tbody>' + brows + "</tbody></table>")
    return out


def _teleop_block(teleop: dict) -> str:
    rows = "".join('<tr><td>{}</td><td class="n">{}</td></tr>'.format(*_field_label_and_value(k, v))
                   for k, v in teleop.items())
    return ('<section id="teleop"><h2>Pick and place</h2>'
            '<table class="data" style="max-width:520px">'
            f"<tbody>{rows}</tbody></table></section>")


def write_report(directory: str) -> str:
    """Writes directory/index.html and its plots; returns the page's path. Raises InputError."""
    if not os.path.isdir(directory):
        raise InputError(f"{directory}: no such directory")
    a = load_assessment(os.path.join(directory, "assessment.json"))
    forces_path = os.path.join(directory, a["forces"]["file"])
    columns = a["forces"]["columns"]
    forces = load_forces(forces_path, columns)
    picture_png, picture_note = None, None
    if a.get("picture"):
        picture_path = os.path.join(directory, a["picture"])
        if os.path.exists(picture_path):
            picture_png = _read_png(picture_path)
        else:
            picture_note = f"{a['picture']} is missing from the report's folder."
            print(f"assessment_report.py: {picture_path}: missing (assessment.json names it); "
                  "the report has no picture", file=sys.stderr)

    plt = _import_matplotlib()
    _style(plt)
    t = forces["t_s"]
    tissues = columns[2:]
    limit_of = {lim["tissue"]: lim["max_force_n"] for lim in a["limits"]}
    plots: list[tuple[str, str, str]] = []  # (file, heading, caption)
    total_file = "force_total.png"
    _force_plot(plt, os.path.join(directory, total_file), t, forces["total_force_n"],
                duration_s=a["duration_s"], limit_n=None, breaches=a["breaches"],
                finds=_finds_on(a, None), ylabel="total force (N)", height_in=3.0)
    used_names = {total_file}
    for tissue in tissues:
        name = f"force_{_file_stem(tissue)}.png"
        k = 2
        while name in used_names:  # "a b" and "a_b" would share a file
            name, k = f"force_{_file_stem(tissue)}_{k}.png", k + 1
        used_names.add(name)
        breaches = [b for b in a["breaches"] if b["tissue"] == tissue]
        _force_plot(plt, os.path.join(directory, name), t, forces[tissue],
                    duration_s=a["duration_s"], limit_n=limit_of.get(tissue), breaches=breaches,
                    finds=_finds_on(a, tissue), ylabel="force (N)", height_in=2.6)
        peak = max(forces[tissue])
        cap = f"Peak {peak:.2f} N"
        cap += (f"; limit {limit_of[tissue]:.1f} N, {len(breaches)} breach"
                f"{'es' if len(breaches) != 1 else ''}" if tissue in limit_of else "; no limit set")
        plots.append((name, _pretty(tissue).capitalize(), cap))

    def img(file: str, alt: str) -> str:
        with open(os.path.join(directory, file), "rb") as f:
            return f'<img src="{_data_uri(f.read())}" alt="{_esc(alt)}">'

    found = sum(1 for lm in a["landmarks"] if lm["found"])
    n_lm = len(a["landmarks"])
    n_breach = len(a["breaches"])
    title = a.get("scene_name") or a["scene"]
    time_limit = a.get("time_limit_s")
    duration = _num(a["duration_s"], 1, "s")
    if time_limit is not None:
        duration += f' <span class="sub">of {time_limit:g} s</span>'
    kpis = []
    if n_lm:
        kpis.append(_kpi("Landmarks found", f"{found} / {n_lm}", "good" if found == n_lm else ""))
    if a["limits"]:
        kpis.append(_kpi("Breaches", str(n_breach), "alert" if n_breach else "good"))
    kpis.append(_kpi("Time", duration, "alert" if a.get("over_time") else ""))
    if a.get("path_length_m") is not None:
        kpis.append(_kpi("Path length", _num(a["path_length_m"] * 100.0, 1, "cm")))
    if a.get("mean_force_n") is not None:
        kpis.append(_kpi("Mean contact force", _num(a["mean_force_n"], 2, "N")))
    if a.get("peak_force_n") is not None:
        kpis.append(_kpi("Peak force", _num(a["peak_force_n"], 2, "N")))

    kind = {"palpation": "Palpation", "pick_and_place": "Pick and place"}.get(
        a.get("kind") or "", _pretty(a.get("kind") or "Training"))
    over = '<p class="flag">Over the time limit.</p>' if a.get("over_time") else ""
    formula = ('<p class="formula"><b>How the score is computed.</b> '
               f'{_esc(a["score"]["formula"])}</p>'
               if a["score"].get("formula") else "")
    header = (f'<header><div><div class="eyebrow">{_esc(kind)} training report</div>'
              f"<h1>{_esc(title)}</h1>"
              f'<p class="meta">Scene <b>{_esc(a["scene"])}</b> · '
              f'Recording <b>{_esc(a["recording"])}</b></p>'
              f'<p class="meta">Session length <b>{_num(a["duration_s"], 1, "s")}</b> · '
              f"Report made {_now_utc()}</p>{over}</div>"
              f"{_score_block(a)}</header>{formula}"
              f'<div class="kpis">{"".join(kpis)}</div>')

    legend = ('<div class="legend">'
              f'<span><i style="background:{FOUND_COLOUR}"></i>landmark found</span>'
              f'<span><i style="background:{MISSED_COLOUR}"></i>landmark missed</span>'
              f'<span><i style="background:{BREACH_COLOUR}"></i>force limit breached '
              "(worst point)</span></div>")
    if picture_png is not None:
        picture = (f'<section id="picture"><h2>The scene at the end of the session</h2><figure>'
                   f'<img src="{_data_uri(picture_png)}" alt="the scene with its landmarks">'
                   f"<figcaption>{legend}</figcaption></figure></section>")
    else:
        why = picture_note or "No picture was drawn for this session."
        picture = (f'<section id="picture"><h2>The scene at the end of the session</h2>'
                   f'<p class="note">{_esc(why)}</p></section>')

    # A pick-and-place session has no landmarks: no empty section for them.
    landmarks = ("" if not a["landmarks"] and a.get("kind") == "pick_and_place" else
                 f'<section id="landmarks"><h2>Landmarks</h2>{_landmark_table(a)}</section>')
    how_to_read = []
    if found:
        how_to_read.append("Numbered green markers: the moment each landmark was found (numbers "
                           "as in the landmark table).")
    if n_breach:
        how_to_read.append("Shaded red: force over the tissue's limit.")
    how_to_read.append("Each point is the maximum force over 10 ms.")
    plot_html = "".join(
        f'<figure style="margin-top:14px"><h3>{_esc(h)}</h3>{img(f, "force on " + h)}'
        f"<figcaption>{_esc(c)}</figcaption></figure>" for f, h, c in plots)
    body = (header + picture
            + landmarks
            + f'<section id="limits"><h2>Force limits</h2>{_limits_tables(a)}</section>'
            + (_teleop_block(a["teleop"]) if a.get("teleop") is not None else "")
            + '<section id="forces"><h2>Forces over time</h2>'
            + f'<p class="sub">{" ".join(how_to_read)}</p>'
            + f'<figure><h3>Total force on the tool</h3>{img(total_file, "total force")}</figure>'
            + plot_html + "</section>"
            + f'<footer>hapsim assess · schema {_esc(a["schema"])} · times in seconds from the '
              "recording's first frame</footer>")
    out = os.path.join(directory, "index.html")
    with open(out, "w", encoding="utf-8") as f:
        f.write(_page(f"{title} — training report", body))
    return out


def _session_row(path: str, a: dict) -> dict:
    missed = sum(1 for lm in a["landmarks"] if not lm["found"])
    return {"path": path, "a": a, "score": a["score"]["value"], "score_max": a["score"]["max"],
            "missed": missed, "breaches": len(a["breaches"]), "duration_s": a["duration_s"],
            "time_limit_s": a.get("time_limit_s"), "landmarks": len(a["landmarks"])}


def write_summary(out_dir: str, json_paths: list[str]) -> str:
    """Writes out_dir/index.html and out_dir/learning_curve.png over the sessions, in the given
    order; returns the page's path. Raises InputError."""
    if not json_paths:
        raise InputError("summary: no assessment.json given (usage: summary OUT_DIR A.json ...)")
    sessions = [_session_row(p, load_assessment(p)) for p in json_paths]
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as e:
        raise InputError(f"{out_dir}: cannot be made ({e.strerror})") from None
    plt = _import_matplotlib()
    _style(plt)
    curve = os.path.join(out_dir, "learning_curve.png")
    _learning_curve(plt, curve, sessions)
    with open(curve, "rb") as f:
        curve_png = f.read()

    rows = []
    for i, s in enumerate(sessions, start=1):
        a = s["a"]
        report = os.path.join(os.path.dirname(os.path.abspath(s["path"])), "index.html")
        rel = os.path.relpath(report, os.path.abspath(out_dir)).replace(os.sep, "/")
        link = (f'<a href="{_esc(rel)}">report</a>' if os.path.exists(report)
                else '<span class="note">no report</span>')
        errors = s["missed"] + s["breaches"]
        found = s["landmarks"] - s["missed"]
        over = ' <span class="flag">over</span>' if a.get("over_time") else ""
        rows.append(
            f'<tr data-session="{i}"><td>{i}</td><td>{_esc(a["recording"])}</td>'
            f'<td class="n"><b>{s["score"]:.1f}</b></td>'
            f'<td class="n">{found} / {s["landmarks"]}</td><td class="n">{s["breaches"]}</td>'
            f'<td class="n" data-errors="{errors}">{errors}</td>'
            f'<td class="n">{_num(s["duration_s"], 1, "s")}{over}</td><td>{link}</td></tr>')
    first, last = sessions[0], sessions[-1]
    scenes = sorted({s["a"].get("scene_name") or s["a"]["scene"] for s in sessions})
    kpis = (_kpi("Sessions", str(len(sessions)))
            + _kpi("Score, first → last", f'{first["score"]:.1f} → {last["score"]:.1f}')
            + _kpi("Errors, first → last", f'{first["missed"] + first["breaches"]} → '
                   f'{last["missed"] + last["breaches"]}')
            + _kpi("Time, first → last",
                   f'{first["duration_s"]:.1f} → {last["duration_s"]:.1f}&nbsp;s'))
    body = (f'<header><div><div class="eyebrow">Training summary</div>'
            f'<h1>{_esc(" · ".join(scenes))}</h1>'
            f'<p class="meta">{len(sessions)} sessions · Summary made {_now_utc()}</p>'
            "</div></header>"
            f'<div class="kpis">{kpis}</div>'
            f'<section id="curve"><h2>Learning curve</h2><figure>'
            f'<img src="{_data_uri(curve_png)}" alt="learning curve"><figcaption>Score, errors '
            "(missed landmarks + force-limit breaches) and time per session. Force feedback "
            "should show as fewer errors and a shorter time to learn the task."
            "</figcaption></figure></section>"
            '<section id="sessions"><h2>Sessions</h2><table class="data"><thead><tr><th>#</th>'
            '<th>Recording</th><th class="n">Score</th><th class="n">Landmarks found</th>'
            '<th class="n">Breaches</th><th class="n">Errors</th><th class="n">Time</th>'
            "<th>Report</th></tr></thead><tbody>" + "".join(rows) + "</tbody></table></section>"
            "<footer>hapsim assess --summary · each session's report opens from its row</footer>")
    out = os.path.join(out_dir, "index.html")
    with open(out, "w", encoding="utf-8") as f:
        f.write(_page("Training summary", body))
    return out


_USAGE = "usage: assessment_report.py report DIR | summary OUT_DIR A.json [B.json ...]"


def main(argv: list[str]) -> int:
    _ensure_matplotlib()  # first: a re-run under /usr/bin/python3 starts from here
    if (len(argv) < 2 or argv[0] not in ("report", "summary")
            or (argv[0] == "report" and len(argv) != 2)):
        _fail(_USAGE)
    try:
        if argv[0] == "report":
            out = write_report(argv[1])
        else:
            if len(argv) < 3:
                _fail(_USAGE)
            out = write_summary(argv[1], argv[2:])
    except InputError as e:
        _fail(str(e))
    except OSError as e:
        _fail(f"{e.filename or 'output'}: cannot be written ({e.strerror})")
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
