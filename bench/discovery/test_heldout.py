#!/usr/bin/python3
"""Checks of heldout.py (the held-out sets' spread). Run: python3 test_heldout.py

Hand-made tables in a temporary folder; each check says what it guards against.
"""
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import heldout  # noqa: E402

HEAD = ("| truth kind | data | cases | named right | parameters within 10 % | 1σ coverage | nulls consistent | "
        "inconclusive | failed | median fit gain | worsened |\n|---|---|---|---|---|---|---|---|---|---|---|\n")


def table(modal, rec, params, nulls, not_right):
    """A table.md with the three '**all**' rows and a list of the cases not right."""
    rows = [("modal", modal, params, nulls), ("recordings", rec, params, nulls), ("both", modal, params, nulls)]
    text = HEAD + "".join(f"| **all** | {d} | 210 | {m} | {p} | 70 % (10) | {n} | 3 % | 0 | 10× | 0 |\n"
                          for d, m, p, n in rows)
    text += "\n## Cases not right\n\n| case | truth | family | dynid said |\n|---|---|---|---|\n"
    text += "".join(f"| {c} | {t} | cantilever | consistent |\n" for c, t in not_right)
    return text + "\n## Cases below the shift floor (not in the named-right rates)\n\n| case | truth |\n|---|---|\n" \
        "| x-9-damage-modal | damage: 1 % |\n"


def check(name, ok):
    print(("ok   " if ok else "FAIL ") + name)
    return ok


def main():
    ok = True
    # Wilson's interval: 8 of 10 at 95 % is [0.4902, 0.9433] (Wilson 1927; the usual published value).
    lo, hi = heldout.wilson(8, 10)
    ok &= check("Wilson 95 % interval of 8/10 is [0.490, 0.943]", abs(lo - 0.4902) < 5e-4 and abs(hi - 0.9433) < 5e-4)
    # Equal rates in every set: no spread beyond sampling (p = 1); very different ones: p tiny.
    ok &= check("identical sets: homogeneity p = 1", abs(heldout.homogeneity_p([(80, 100), (80, 100)]) - 1) < 1e-12)
    ok &= check("50 % against 90 %: p < 1e-6", heldout.homogeneity_p([(50, 100), (90, 100)]) < 1e-6)
    with tempfile.TemporaryDirectory() as d:
        for name in ("test", "test2", "dev"):
            os.makedirs(os.path.join(d, name))
        # 91 % of 11 reads as 10 of 11; the list of cases not right says 9 (two modal misses): the exact count wins.
        with open(os.path.join(d, "test", "table.md"), "w") as f:
            f.write(table("91 % (11)", "50 % (4)", "80 % (10)", "50 % (2)",
                          [("x-1-damage-modal", "damage: 5 %"), ("x-2-damage-modal", "damage: 4 %"),
                           ("x-3-damage-rec", "damage: 3 %"), ("x-4-damage-rec", "damage: 3 %"),
                           ("x-5-null-rec", "null: null")]))
        with open(os.path.join(d, "test2", "table.md"), "w") as f:
            f.write(table("100 % (5)", "100 % (5)", "100 % (5)", "100 % (2)", []))
        with open(os.path.join(d, "dev", "table.md"), "w") as f:   # tuned on: never a held-out set
            f.write(table("0 % (5)", "0 % (5)", "0 % (5)", "0 % (2)", []))
        sets = heldout.held_out_sets(d)
        ok &= check("held-out sets in drawing order, dev left out", [n for n, _ in sets] == ["test", "test2"])
        path = sets[0][1]
        rows, missed = heldout.all_rows(path), heldout.misses(path)
        ok &= check("named right counted from the cases not right (9 of 11, not the rounded 10)",
                    heldout.exact(rows, missed, path, "modal", 3) == (9, 11, True))
        ok &= check("recordings: 2 of 4", heldout.exact(rows, missed, path, "recordings", 3) == (2, 4, True))
        ok &= check("nulls: 1 of 2", heldout.exact(rows, missed, path, "both", 6) == (1, 2, True))
        ok &= check("parameters from the rounded rate, marked inexact",
                    heldout.exact(rows, missed, path, "both", 4) == (8, 10, False))
        out = subprocess.run([sys.executable, str(HERE / "heldout.py"), "--results", d, "--out",
                              os.path.join(d, "h.png")], capture_output=True, text=True)
        ok &= check("the command prints the pooled rates and writes the figure",
                    out.returncode == 0
                    and "| modal data named right | 9/11 (81.8 %) | 5/5 (100.0 %) | 14/16" in out.stdout
                    and os.path.getsize(os.path.join(d, "h.png")) > 10000)
        # A table without its '**all**' rows is refused with the file and what is missing, not a traceback.
        with open(os.path.join(d, "test2", "table.md"), "w") as f:
            f.write(HEAD)
        out = subprocess.run([sys.executable, str(HERE / "heldout.py"), "--results", d, "--out",
                              os.path.join(d, "h2.png")], capture_output=True, text=True)
        ok &= check("a table without its totals: a clear error naming the file",
                    out.returncode != 0 and "test2/table.md: expected the '**all**' rows" in out.stderr
                    and "Traceback" not in out.stderr)
    print("all checks passed" if ok else "some checks FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
