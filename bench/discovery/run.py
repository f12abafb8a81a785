#!/usr/bin/python3
"""The concealed-physics benchmark in one command: generate a split, run `dynid discover` on every case, score,
report (results.json, table.md, confusion.png, parameters.png).

  run.py [--split dev|test] [--subset ci] [--limit N] [--cases DIR [--rescore]] [--out DIR] [--keep]
         [--dynid PATH] [--jobs 2] [--timeout S] [--check]

Each worker generates a case, runs dynid on it (one thread) and scores it, so at most --jobs dynid processes
run at a time. dynid's failures (exit code, last line of its error output) are scored as wrong, never fatal.
--check exits with 1 when an acceptance threshold is missed, printing which.
"""
import argparse
import json
import math
import multiprocessing
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS"):   # one BLAS thread per worker (set before numpy loads)
    os.environ.setdefault(_v, "1")

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import generate   # noqa: E402
import ideal      # noqa: E402
import score      # noqa: E402

ROOT = HERE.parent.parent
CI_CASES = 48        # the CI subset: the first cases of the split (one of every kind x source, then more)
# The goals (issue 15's acceptance), and the floors the CI check holds the CI subset to: what discovery reached
# on that subset when the floor was last raised, less a margin for one or two cases; a regression guard, not
# the goal. Reported numbers come from the test split with the goals.
THRESHOLDS = dict(modal_named_right=0.90, recordings_named_right=0.80, parameters_within=0.80,
                  coverage=(0.60, 0.76), null_consistent=0.95, worsened=0)
FLOORS = dict(modal_named_right=0.70, recordings_named_right=0.38, parameters_within=0.55,
              coverage=(0.25, 1.0), null_consistent=0.70, worsened=0)
KIND_ORDER = list(generate.KIND_COUNTS)
CANDIDATE = dict(ideal.CANDIDATE, null="consistent")   # each truth kind's own candidate, for the figure's order


def regression_check(index, checks, prefix):
    """One dev case as a regression check (test_expected_shape.py, test_lowest_mode.py; argv: DYNID [WORKDIR]):
    generated, run and scored as the benchmark does (recordings kept, so that the case can be looked at); then
    checks(score, truth, discover_json) returns the failures. Prints them; returns the exit code."""
    dynid = sys.argv[1]
    work = Path(sys.argv[2]) if len(sys.argv) > 2 else Path(tempfile.mkdtemp(prefix=prefix))
    work.mkdir(parents=True, exist_ok=True)
    sc = run_case((None, "dev", index, dict(out=str(work), dynid=dynid, timeout=120, keep=True)))
    if sc["failure"]:
        print(f"FAIL: {sc['failure']}")
        return 1
    folder = work / sc["case"]
    failures = checks(sc, json.loads((folder / "truth.json").read_text()),
                      json.loads((folder / "discover.json").read_text()))
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


def run_case(job):
    """Generate (unless the case exists), run dynid, score. Never raises: failures are part of the score."""
    folder, split, index, a = job
    generated = folder is None
    t0 = time.time()
    failure = None
    try:
        if generated:
            rec = generate.make_case(split, index, a["out"])
            folder = Path(a["out"]) / rec["case"]
        truth = json.loads((Path(folder) / "truth.json").read_text())
    except Exception as exc:   # a generator failure must not stop the benchmark; it is reported
        return dict(case=f"{split}-{index:03d}", kind=generate.split_plan(split)[index][0], source="?",
                    family="?", failure=f"generation failed: {exc!r}", verdict="failed", named=None,
                    named_right=False, null=False, null_right=False, inconclusive=False, within=None,
                    covered=None, fit=None, worsened=False, said=f"generation failed: {exc!r}",
                    seconds_generate=time.time() - t0, seconds_dynid=0.0)
    t1 = time.time()
    out_json, out_png = Path(folder) / "discover.json", Path(folder) / "discover.png"
    # A failed run leaves its message here and no discover.json, so that a rescore scores what this run did, never
    # an older run's result.
    out_failed = Path(folder) / "discover.failed"
    result, rc = None, None
    if a.get("rescore"):   # score the result dynid wrote before (a scoring or report change), never run it
        if out_failed.exists():
            failure = out_failed.read_text().strip()
        elif out_json.exists():
            result = json.loads(out_json.read_text())
        else:
            failure = "no discover.json"
    else:
        for f in (out_json, out_png, out_failed):
            f.unlink(missing_ok=True)
        cmd = [a["dynid"], "--threads", "1", "-q", "discover", str(folder), "--json", str(out_json),
               "--plot", str(out_png), "--force"]
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=a["timeout"])
            rc = p.returncode
            lines = [l for l in (p.stderr or "").splitlines() if l.strip()]
            if rc in (0, 4) and out_json.exists():
                result = json.loads(out_json.read_text())
            else:
                failure = f"exit {rc}: {lines[-1] if lines else '(no message)'}"
        except subprocess.TimeoutExpired:
            failure = f"timeout after {a['timeout']} s"
        if failure:
            out_json.unlink(missing_ok=True)
            out_failed.write_text(failure + "\n")
    t2 = time.time()
    sc = score.score(truth, result, failure)
    sc.update(exit_code=rc, seconds_generate=t1 - t0, seconds_dynid=t2 - t1,
              truth_effects=[e["description"] for e in truth["effects"]], dofs=truth["structure"]["dofs"],
              shift_pct=truth["shift_pct"], data=truth["data"])
    if generated and not a["keep"] and truth["source"] == "recordings":   # never delete a --cases folder's data
        for f in truth["data"]["files"]:
            (Path(folder) / f).unlink(missing_ok=True)
    return sc


def rate(num, den):
    return None if den == 0 else num / den


def summarize(cases):
    """Rates of one group of scored cases."""
    nonnull = [c for c in cases if not c["null"] and not c.get("below_floor")]
    named = [c for c in nonnull if c["named_right"]]
    with_ref = [c for c in named if c.get("within") is not None]
    with_std = [c for c in named if c.get("covered") is not None]
    nulls = [c for c in cases if c["null"]]
    gains = sorted(c["fit"]["max_freq_error_before"] / max(c["fit"]["max_freq_error_after"], 1e-12)
                   for c in cases if c.get("fit") and c["fit"].get("max_freq_error_after") is not None
                   and c["verdict"] == "missing_physics")
    return dict(cases=len(cases), nonnull=len(nonnull), named_right=rate(len(named), len(nonnull)),
                parameters_within=rate(sum(c["within"] for c in with_ref), len(with_ref)), with_reference=len(with_ref),
                coverage=rate(sum(c["covered"] for c in with_std), len(with_std)), with_std=len(with_std),
                nulls=len(nulls), null_consistent=rate(sum(c["null_right"] for c in nulls), len(nulls)),
                inconclusive=rate(sum(c["inconclusive"] for c in cases), len(cases)),
                failed=sum(c["verdict"] == "failed" for c in cases),
                below_floor=sum(bool(c.get("below_floor")) for c in cases),
                median_fit_gain=gains[len(gains) // 2] if gains else None,
                worsened=sum(bool(c.get("worsened")) for c in cases),
                worsened_strict=sum(bool(c.get("worsened_strict")) for c in cases))


def report(cases):
    by_kind = {k: summarize([c for c in cases if c["kind"] == k]) for k in KIND_ORDER if any(c["kind"] == k for c in cases)}
    by_source = {s: summarize([c for c in cases if c["source"] == s]) for s in ("modal", "recordings")}
    by_kind_source = {f"{k}/{s}": summarize([c for c in cases if c["kind"] == k and c["source"] == s])
                      for k in KIND_ORDER for s in ("modal", "recordings")
                      if any(c["kind"] == k and c["source"] == s for c in cases)}
    return dict(by_kind=by_kind, by_source=by_source, by_kind_source=by_kind_source, overall=summarize(cases))


def acceptance(rep, th=THRESHOLDS):
    """[(name, value, threshold text, ok)] for --check, against `th` (THRESHOLDS or FLOORS)."""
    s, o = rep["by_source"], rep["overall"]
    THRESHOLDS = th

    def txt(key):
        v = th[key]
        return f"{100 * v[0]:.0f}-{100 * v[1]:.0f} %" if isinstance(v, tuple) else f">= {100 * v:.0f} %"
    out = []

    def add(name, v, text, ok):
        out.append((name, v, text, bool(ok)))
    add("modal data: named right (non-null)", s["modal"]["named_right"], txt("modal_named_right"),
        s["modal"]["named_right"] is not None and s["modal"]["named_right"] >= THRESHOLDS["modal_named_right"])
    add("recordings: named right (non-null)", s["recordings"]["named_right"], txt("recordings_named_right"),
        s["recordings"]["named_right"] is not None and s["recordings"]["named_right"] >= THRESHOLDS["recordings_named_right"])
    add("parameters within 10 % (named right)", o["parameters_within"], txt("parameters_within"),
        o["parameters_within"] is not None and o["parameters_within"] >= THRESHOLDS["parameters_within"])
    lo, hi = THRESHOLDS["coverage"]
    add("1-sigma coverage (named right)", o["coverage"], txt("coverage"),
        o["coverage"] is not None and lo <= o["coverage"] <= hi)
    add("nulls consistent", o["null_consistent"], txt("null_consistent"),
        o["null_consistent"] is not None and o["null_consistent"] >= THRESHOLDS["null_consistent"])
    add(f"findings that worsen max frequency error or mean MAC (any change at all: {o['worsened_strict']})",
        o["worsened"], "= 0", o["worsened"] == 0)
    return out


def pct(v):
    return "–" if v is None else f"{100 * v:.0f} %"


def parameter_lines(cases):
    """Parameters against what the data allow (a diagnosis): by the stated 1-sigma, how many are within 10 % and
    how many a calibrated, unbiased estimate of that 1-sigma would put there; and against the candidate's own best
    value on the truth's noise-free frequencies where the finding sits at its site (score.py, `ideal_site`)."""
    par = [c for c in cases if c["named_right"] and not c.get("below_floor") and c.get("within") is not None]
    if not par:
        return []
    lines = ["", "## Parameters against what the data allow", "",
             "Cases named right with a reference, by the 1σ dynid states (relative to its value); `expected`: the "
             "number within 10 % were every stated 1σ exact and every estimate unbiased (score.py `expected_within`).",
             "", "| stated 1σ | cases | within 10 % | 1σ covers | expected within 10 % |", "|---|---|---|---|---|"]
    def rel(c):
        p = c["parameter"]
        return abs(p["std"] / p["value"]) if p.get("std") is not None and p.get("value") else math.inf
    for label, lo, hi in (("< 6 %", 0, 0.06), ("6–10 %", 0.06, 0.10), ("10–20 %", 0.10, 0.20), ("≥ 20 % or none", 0.20, math.inf)):
        b = [c for c in par if lo <= rel(c) < hi or (hi == math.inf and rel(c) == math.inf)]
        if b:
            lines.append(f"| {label} | {len(b)} | {sum(c['within'] for c in b)} | {sum(bool(c.get('covered')) for c in b)} | "
                         f"{sum(c.get('expected_within', 0.0) for c in b):.1f} |")
    lines.append(f"| all | {len(par)} | {sum(c['within'] for c in par)} | {sum(bool(c.get('covered')) for c in par)} | "
                 f"{sum(c.get('expected_within', 0.0) for c in par):.1f} |")
    at = [c for c in par if c.get("within_ideal") is not None]
    if at:
        lines += ["", f"Against the candidate's own best value on the truth's noise-free frequencies (truth.json "
                  f"`effects[].ideal`), for the {len(at)} findings at the ideal candidate's site: "
                  f"{sum(c['within_ideal'] for c in at)} within 10 % (of the reference: {sum(c['within'] for c in at)})."]
    return lines


def table(rep, cases, checks, meta):
    rows = ["| truth kind | data | cases | named right | parameters within 10 % | 1σ coverage | nulls consistent | "
            "inconclusive | failed | median fit gain | worsened |", "|---|---|---|---|---|---|---|---|---|---|---|"]

    def row(label, src, g):
        gain = "–" if g["median_fit_gain"] is None else f"{g['median_fit_gain']:.3g}×"
        named = f"{pct(g['named_right'])} ({g['nonnull']})" if g["nonnull"] else "–"
        par = f"{pct(g['parameters_within'])} ({g['with_reference']})" if g["with_reference"] else "–"
        cov = f"{pct(g['coverage'])} ({g['with_std']})" if g["with_std"] else "–"
        nul = f"{pct(g['null_consistent'])} ({g['nulls']})" if g["nulls"] else "–"
        rows.append(f"| {label} | {src} | {g['cases']} | {named} | {par} | {cov} | {nul} | {pct(g['inconclusive'])} | "
                    f"{g['failed']} | {gain} | {g['worsened']} |")
    for key, g in rep["by_kind_source"].items():
        k, s = key.split("/")
        row(k, s, g)
    for s, g in rep["by_source"].items():
        if g["cases"]:
            row("**all**", s, g)
    row("**all**", "both", rep["overall"])
    lines = [f"# Concealed-physics benchmark: {meta['label']}", "",
             f"{meta['cases']} cases, dynid `{meta['dynid']}`, {meta['wall_s']:.0f} s wall on {meta['jobs']} workers "
             f"(generation {meta['generate_s']:.0f} s, dynid {meta['dynid_s']:.0f} s of CPU-process time).", "",
             "Counts in parentheses: the cases each rate is over (non-null cases; correctly named with a reference; "
             "with a stated 1σ; nulls). Non-null cases whose effects do not reach the benchmark's lower bound on the "
             f"shift (score.py, `below_floor`: {rep['overall']['below_floor']} here) are listed at the end and left "
             "out of the named-right rates.", ""] + rows + ["", "## Acceptance", "", "| check | value | threshold | met |",
                                                       "|---|---|---|---|"]
    for name, v, text, ok in checks:
        val = str(v) if isinstance(v, int) else pct(v)
        lines.append(f"| {name} | {val} | {text} | {'yes' if ok else '**no**'} |")
    lines += ["", "## Stated probability against outcome", "",
              "Non-null cases with verdict missing_physics, by the probability dynid states for its findings against "
              "their rivals (JSON `probability`); a calibrated statement is right about as often as it says.", "",
              "| stated probability | claims | mean stated | named right |", "|---|---|---|---|"]
    claims = [c for c in cases if not c["null"] and c["verdict"] == "missing_physics" and c.get("probability") is not None]
    for lo, hi in ((0.5, 0.7), (0.7, 0.9), (0.9, 0.99), (0.99, 1.01)):
        b = [c for c in claims if lo <= c["probability"] < hi]
        if b:
            lines.append(f"| {lo:g}–{min(hi, 1):g} | {len(b)} | {pct(sum(c['probability'] for c in b) / len(b))} | "
                         f"{pct(sum(c['named_right'] for c in b) / len(b))} |")
    lines += parameter_lines(cases)

    def truth_and_said(c, width):
        truth = "null" if c["null"] else "; ".join(c.get("truth_effects", [])) or c["kind"]
        return f"{c['kind']}: {truth}", c["said"].replace("|", "/").replace("\n", " ")[:width]

    lines += ["", "## Cases not right", "", "| case | truth | family | dynid said |", "|---|---|---|---|"]
    for c in cases:
        right = c["null_right"] if c["null"] else c["named_right"]
        if right or c.get("below_floor"):
            continue
        truth, said = truth_and_said(c, 400)
        lines.append(f"| {c['case']} | {truth} | {c['family']} | {said} |")
    floor = [c for c in cases if c.get("below_floor")]
    if floor:
        lines += ["", "## Cases below the shift floor (not in the named-right rates)", "",
                  "Their effects shift the data's modes by less than the benchmark's lower bound, max(0.5 %, 5 σ_f): "
                  "the generator kept its last draw when none reached it.", "",
                  "| case | truth | shift of the data's modes | lower bound | dynid said |", "|---|---|---|---|---|"]
        for c in floor:
            truth, said = truth_and_said(c, 200)
            lines.append(f"| {c['case']} | {truth} | {c['effect_shift_pct']:.3g} % | "
                         f"{c.get('shift_floor_pct', 0):.3g} % | {said} |")
    return "\n".join(lines) + "\n"


def figures(cases, out):
    """confusion.png (true kind x first named kind) and parameters.png (reported / reference, named right)."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np
    except ImportError:
        print("matplotlib not installed: no figures (apt-get install python3-matplotlib)")
        return []
    rows = [k for k in KIND_ORDER if any(c["kind"] == k for c in cases)]
    named = []
    for c in cases:
        n = c["named"] or c["verdict"]
        if n not in named:
            named.append(n)
    # Columns in the order of the rows' own candidates (a right answer lies on the diagonal), then the rest.
    tail = [n for n in ("consistent", "inconclusive", "failed") if n in named]
    diag = [CANDIDATE.get(k) for k in rows]
    cols = [n for n in diag if n in named and n not in tail]
    cols += sorted(n for n in named if n not in cols and n not in tail) + tail
    M = np.zeros((len(rows), len(cols)), int)
    for c in cases:
        M[rows.index(c["kind"]), cols.index(c["named"] or c["verdict"])] += 1
    fig, ax = plt.subplots(figsize=(1.0 + 0.55 * len(cols), 1.2 + 0.42 * len(rows)))
    ax.imshow(M / np.maximum(M.sum(axis=1, keepdims=True), 1), cmap="Blues", vmin=0, vmax=1, aspect="auto")
    for i in range(len(rows)):
        for j in range(len(cols)):
            if M[i, j]:
                ax.text(j, i, M[i, j], ha="center", va="center", fontsize=8,
                        color="white" if M[i, j] > 0.6 * M[i].sum() else "black")
    ax.set_xticks(range(len(cols)), cols, rotation=60, ha="right", fontsize=8)
    ax.set_yticks(range(len(rows)), rows, fontsize=8)
    ax.set_xlabel("first finding (or verdict) of dynid")
    ax.set_ylabel("truth kind")
    ax.set_title("truth kind x dynid's first finding (counts; colour: share of the row)", fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "confusion.png", dpi=130)
    plt.close(fig)
    pts = [(c["kind"], c["parameter"]["value"] / c["reference"]) for c in cases
           if c.get("named_right") and c.get("reference") and c.get("parameter") and c["parameter"].get("value")
           and c["parameter"]["unit"] == c["parameter"]["expected_unit"]]
    files = ["confusion.png"]
    if pts:
        kinds = [k for k in rows if any(p[0] == k for p in pts)]
        fig, ax = plt.subplots(figsize=(7, 0.5 + 0.35 * len(kinds)))
        for i, k in enumerate(kinds):
            r = [abs(v) for kk, v in pts if kk == k]
            ax.plot(r, [i] * len(r), "o", alpha=0.6, ms=4)
        ax.axvspan(0.9, 1.1, color="green", alpha=0.15)
        ax.invert_yaxis()                     # the rows in the order of the confusion matrix
        ax.set_xscale("log")
        ax.set_yticks(range(len(kinds)), kinds, fontsize=8)
        ax.set_xlabel("reported parameter / reference (cases named right); green: within 10 %")
        fig.tight_layout()
        fig.savefig(out / "parameters.png", dpi=130)
        plt.close(fig)
        files.append("parameters.png")
    return files


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--split", choices=sorted(generate.MASTER_SEED), default="dev")
    ap.add_argument("--subset", choices=["ci"])
    ap.add_argument("--limit", type=int, help="the first N cases (of the split or subset)")
    ap.add_argument("--cases", help="run and score existing case folders (each with case.yaml and truth.json), "
                                    "e.g. made by generate.py or kept by --keep; their data are never deleted")
    ap.add_argument("--out", help="output folder (default build/bench-discovery/<split>[-ci])")
    ap.add_argument("--keep", action="store_true", help="keep the recordings (deleted after scoring by default)")
    ap.add_argument("--rescore", action="store_true", help="with --cases: score the discover.json each folder holds "
                                                           "(a scoring or report change) without running dynid")
    ap.add_argument("--dynid", default=str(ROOT / "build" / "cli" / "dynid"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per dynid run")
    ap.add_argument("--check", nargs="?", const="goal", choices=["goal", "floor"],
                    help="exit 1 when a threshold is missed: the goals (default) or the CI floors")
    a = ap.parse_args()
    label = a.split + ("-ci" if a.subset else "")
    out = Path(a.out or ROOT / "build" / "bench-discovery" / label).resolve()
    out.mkdir(parents=True, exist_ok=True)
    if not Path(a.dynid).exists():
        sys.exit(f"dynid not found at {a.dynid} (build it, or give --dynid)")
    if a.rescore and not a.cases:
        sys.exit("--rescore needs --cases (the folders holding the discover.json to score)")
    opts = dict(out=str(out / "cases"), dynid=str(Path(a.dynid).resolve()), keep=a.keep, timeout=a.timeout,
                rescore=a.rescore)
    if a.cases:
        folders = sorted(p.parent for p in Path(a.cases).glob("*/truth.json"))
        jobs = [(f, None, None, opts) for f in folders]
        label = f"cases in {a.cases}"
    else:
        n = len(generate.split_plan(a.split))
        idx = list(range(min(CI_CASES, n) if a.subset == "ci" else n))
        jobs = [(None, a.split, i, opts) for i in idx]
    jobs = jobs[:a.limit] if a.limit else jobs
    t0 = time.time()
    cases = []
    with multiprocessing.Pool(a.jobs) as pool:
        for k, c in enumerate(pool.imap(run_case, jobs), 1):
            cases.append(c)
            right = c["null_right"] if c["null"] else c["named_right"]
            print(f"[{k}/{len(jobs)}] {c['case']}: {'right' if right else 'WRONG'} — {c['said'][:110]} "
                  f"({c['seconds_generate']:.1f} + {c['seconds_dynid']:.1f} s)", flush=True)
    wall = time.time() - t0
    rep = report(cases)
    checks = acceptance(rep, FLOORS if a.check == "floor" else THRESHOLDS)
    meta = dict(label=label, cases=len(cases), dynid=opts["dynid"], jobs=a.jobs, wall_s=wall,
                generate_s=sum(c["seconds_generate"] for c in cases), dynid_s=sum(c["seconds_dynid"] for c in cases))
    (out / "results.json").write_text(json.dumps(dict(meta=meta, report=rep, acceptance=[
        dict(check=n, value=v, threshold=t, met=ok) for n, v, t, ok in checks], cases=cases), indent=1) + "\n")
    (out / "table.md").write_text(table(rep, cases, checks, meta))
    files = figures(cases, out)
    print(f"\n{len(cases)} cases in {wall:.0f} s; results in {out}: results.json, table.md, " + ", ".join(files))
    for name, v, text, ok in checks:
        print(f"  {'ok  ' if ok else 'MISS'} {name}: {v if isinstance(v, int) else pct(v)} (threshold {text})")
    if a.check and not all(ok for *_, ok in checks):
        sys.exit(1)


if __name__ == "__main__":
    main()
