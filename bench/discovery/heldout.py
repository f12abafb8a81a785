#!/usr/bin/python3
"""How far the held-out rates move from one fresh draw to the next.

  heldout.py [--results DIR] [--out PNG]

Reads the "all" rows of every held-out table in results/ (test, ci-rest, test2, test3, ...; not dev, which is
tuned on) and prints, per acceptance rate, each set's count, the pooled rate with its 95 % Wilson interval, and
whether the sets' spread is larger than their binomial sampling noise (chi-square test of homogeneity over the
sets); writes a figure of the same with each set's 95 % Wilson interval (default results/heldout.png). Named-right
and null counts are exact (from each table's list of the cases not right); parameters within 10 % are read from the
rounded rate (marked ~, within one case per set). Each set was run at the commit its table names: the sets measure
several heads, so a spread beyond sampling noise can be a rule's effect as well as the draw's.
"""
import argparse
import math
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

# (label, data row, column of the table, goal: a lower bound)
RATES = [("modal data named right", "modal", 3, 0.90),
         ("recordings named right", "recordings", 3, 0.80),
         ("parameters within 10 %", "both", 4, 0.80),
         ("nulls consistent", "both", 6, 0.95)]


def held_out_sets(results):
    """(name, path of table.md) of the held-out sets, in the order they were drawn."""
    def order(name):
        if name == "test":
            return 0
        if name == "ci-rest":
            return 0.5
        m = re.fullmatch(r"test(\d+)", name)
        return int(m.group(1)) if m else None
    names = [n for n in os.listdir(results)
             if order(n) is not None and os.path.isfile(os.path.join(results, n, "table.md"))]
    return [(n, os.path.join(results, n, "table.md")) for n in sorted(names, key=order)]


def all_rows(path):
    """{data: [cells]} of the table's '**all**' rows."""
    rows = {}
    with open(path) as f:
        for line in f:
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) > 7 and cells[0] == "**all**":
                rows[cells[1]] = cells
    if set(rows) != {"modal", "recordings", "both"}:
        sys.exit(f"{path}: expected the '**all**' rows for modal, recordings and both; found {sorted(rows)}")
    return rows


def count(cell, path):
    """'90 % (181)' -> (hits, n): the table rounds rates to a whole percent, so hits is the count nearest to it
    (within one for n < 200)."""
    m = re.fullmatch(r"(\d+(?:\.\d+)?) % \((\d+)\)", cell)
    if not m:
        sys.exit(f"{path}: cannot read a rate from '{cell}' (expected 'P % (N)')")
    n = int(m.group(2))
    return round(float(m.group(1)) / 100 * n), n


def misses(path):
    """{'modal': non-null cases not right, 'rec': ..., 'null': null cases not right} from the table's list of the
    cases not right (exact counts, where the rates above are rounded)."""
    out = {"modal": 0, "rec": 0, "null": 0}
    inside = False
    with open(path) as f:
        for line in f:
            if line.startswith("## "):
                inside = line.startswith("## Cases not right")
                continue
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if not inside or len(cells) < 4 or not re.match(r"[\w-]+-(modal|rec)$", cells[0]):
                continue
            out["null" if cells[1].startswith("null") else cells[0].rsplit("-", 1)[1]] += 1
    return out


def exact(rows, missed, path, row, col):
    """(hits, n, exact) of a rate from a table's rows and misses (all_rows, misses): named right and nulls counted
    from the cases not right, others from the rounded rate."""
    k, n = count(rows[row][col], path)
    if col == 3 and row in ("modal", "recordings"):
        return n - missed["modal" if row == "modal" else "rec"], n, True
    if col == 6:
        return n - missed["null"], n, True
    return k, n, False


def wilson(k, n, z=1.96):
    if n == 0:
        return 0.0, 1.0
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return c - h, c + h


def homogeneity_p(counts):
    """p-value of the chi-square test that every set has the same rate (the pooled one)."""
    from scipy.stats import chi2
    K, N = sum(k for k, _ in counts), sum(n for _, n in counts)
    p = K / N
    if p in (0, 1):
        return 1.0
    x2 = sum((k - n * p) ** 2 / (n * p * (1 - p)) for k, n in counts)
    return float(chi2.sf(x2, len(counts) - 1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--results", default=os.path.join(HERE, "results"))
    ap.add_argument("--out", default=None, help="figure (default RESULTS/heldout.png)")
    a = ap.parse_args()
    sets = held_out_sets(a.results)
    if not sets:
        sys.exit(f"{a.results}: no held-out tables (test*/table.md, ci-rest/table.md)")
    table = {name: (all_rows(path), misses(path)) for name, path in sets}  # each file read once per part
    summary = []
    print("| rate | " + " | ".join(n for n, _ in sets) +
          " | pooled (95 % interval) | spread beyond sampling (p) | goal |")
    print("|---|" + "---|" * (len(sets) + 3))
    for label, row, col, goal in RATES:
        rated = [exact(*table[n], p, row, col) for n, p in sets]
        counts = [(k, n) for k, n, _ in rated]
        approx = "" if all(e for _, _, e in rated) else "~"
        K, N = sum(k for k, _ in counts), sum(n for _, n in counts)
        p = homogeneity_p(counts)
        summary.append((label, counts, K, N, p, goal))
        cells = [f"{approx}{k}/{n} ({100 * k / n:.1f} %)" for k, n in counts]
        lo, hi = wilson(K, N)
        print(f"| {label} | " + " | ".join(cells) + f" | {approx}{K}/{N} ({100 * K / N:.1f} %, "
              f"{100 * lo:.1f}-{100 * hi:.1f}) | {p:.2f} | {100 * goal:.0f} % |")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(RATES), figsize=(4 * len(RATES), 3.6), sharey=False)
    names = [n for n, _ in sets]
    for ax, (label, counts, K, N, p, goal) in zip(axes, summary):
        x = list(range(len(counts)))
        r = [k / n for k, n in counts]
        lo = [r[i] - wilson(*counts[i])[0] for i in x]
        hi = [wilson(*counts[i])[1] - r[i] for i in x]
        ax.errorbar(x, [100 * v for v in r], yerr=[[100 * v for v in lo], [100 * v for v in hi]], fmt="o",
                    color="C0", capsize=3, label="set (95 % Wilson)")
        ax.axhline(100 * K / N, color="C0", lw=1, ls="--", label=f"pooled {100 * K / N:.1f} %")
        ax.axhline(100 * goal, color="C3", lw=1.2, label=f"goal {100 * goal:.0f} %")
        ax.set_xticks(x, names, rotation=45, ha="right", fontsize=8)
        ax.set_title(f"{label}\nspread beyond sampling: p = {p:.2f}", fontsize=9)
        ax.set_ylabel("%")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower left")
    fig.suptitle("Discovery on held-out sets (each at the commit its table names)", fontsize=10)
    fig.tight_layout()
    out = a.out or os.path.join(a.results, "heldout.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
