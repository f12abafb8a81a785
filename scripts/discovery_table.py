#!/usr/bin/env python3
"""Builds the results table of the discovery suite from dynid discover's JSON files and writes it into a README
between the markers <!-- results --> and <!-- /results --> (stdlib only).
Usage: discovery_table.py RESULTS_DIR README SEEDS"""
import json
import os
import sys


def fmt_params(f):
    out = []
    for k, v in f["parameters"].items():
        unit = f.get("units", {}).get(k, "")
        out.append(f"{k} {v:.4g}{(' ' + unit) if unit else ''}")
    return "; ".join(out)


def main():
    rdir, readme, seeds = sys.argv[1], sys.argv[2], int(sys.argv[3])
    rows = []
    fails = 0
    for name in sorted(os.listdir(rdir)):
        if not name.endswith(".json"):
            continue
        j = json.load(open(os.path.join(rdir, name)))
        first = j["findings"][0] if j["findings"] else None
        loc = ""
        if first and not first["location"]["global"]:
            loc = " ".join([f"n{n}" for n in first["location"]["nodes"]] + [f"e{e}" for e in first["location"]["elements"]])
        elif first:
            loc = "global"
        b, a = j["fit"]["before"], j["fit"]["after"]
        gain = b["max_freq_error_pct"] / max(a["max_freq_error_pct"], 1e-12) if first else float("nan")
        ok = j.get("check", {}).get("ok")
        fails += ok is False
        rob = j.get("robustness")
        rows.append("| {} | {} | {} | {} | {} | {:.3g} → {:.3g} ({}) | {:.4f} → {:.4f} | {} | {} | {:.1f} |".format(
            j["case"], j["verdict"], first["kind"] if first else "—", loc, fmt_params(first) if first else "—",
            b["max_freq_error_pct"], a["max_freq_error_pct"], f"{gain:.0f}×" if first else "—", b["mean_mac"], a["mean_mac"],
            "yes" if ok else ("**no**" if ok is False else "—"),
            f"{rob['as_expected']}/{rob['seeds']} (worst parameter error {100 * rob['worst_parameter_error']:.1f} %)" if rob else "—",
            j["cost"]["seconds"]))
    head = ("| case | verdict | first finding | where | fitted | max freq. error % before → after (gain) | mean MAC before → after | "
            "as expected | robustness (seeds) | s |\n|---|---|---|---|---|---|---|---|---|---|")
    table = head + "\n" + "\n".join(rows) + "\n"
    text = open(readme).read()
    a, b = text.index("<!-- results -->"), text.index("<!-- /results -->")
    text = text[:a] + "<!-- results -->\n" + table + text[b:]
    open(readme, "w").write(text)
    print(table)
    print(f"{len(rows) - fails} of {len(rows)} cases as expected")


if __name__ == "__main__":
    main()
