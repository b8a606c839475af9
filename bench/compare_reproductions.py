"""Compare two sets of ``hsgeo reproduce CHAPTER --json`` outputs, row by row (timings aside).

Used for the re-layering's invariance check (issue 11): save the JSON of every chapter before
and after a change that must not change any number, then

    python bench/compare_reproductions.py BEFORE_DIR AFTER_DIR [--out RESULT.json]

prints, per file, the largest relative change of ``paper``, ``paper_sigma``, ``reproduced``,
``sigma`` and ``truth`` over all rows, and every value that moved by more than ``--rtol``
(default 1e-9) with its absolute change.
"""

import argparse
import json
import math
from pathlib import Path

KEYS = ("paper", "paper_sigma", "reproduced", "sigma", "truth")


def compare(a: dict, b: dict, rtol: float) -> dict:
    ra, rb = a["rows"], b["rows"]
    if len(ra) != len(rb):
        return {"error": f"{len(ra)} rows against {len(rb)}"}
    worst, over = 0.0, []
    for x, y in zip(ra, rb, strict=True):
        if (x["table"], x["quantity"], x["unit"]) != (y["table"], y["quantity"], y["unit"]):
            return {"error": f"row {x['quantity']!r} against {y['quantity']!r}"}
        for k in KEYS:
            u, v = x[k], y[k]
            if u is None or v is None:
                if u != v:
                    over.append(
                        {
                            "table": x["table"],
                            "quantity": x["quantity"],
                            "field": k,
                            "before": u,
                            "after": v,
                        }
                    )
                    worst = math.inf
                continue
            d = abs(u - v) / max(abs(u), abs(v)) if u != v else 0.0
            if d > rtol:
                over.append(
                    {
                        "table": x["table"],
                        "quantity": x["quantity"],
                        "field": k,
                        "before": u,
                        "after": v,
                        "abs_change": abs(u - v),
                    }
                )
            worst = max(worst, d)
    rest = [0.0]
    over_keys = {(o["table"], o["quantity"], o["field"]) for o in over}
    for x, y in zip(ra, rb, strict=True):
        for k in KEYS:
            u, v = x[k], y[k]
            if None in (u, v) or u == v or (x["table"], x["quantity"], k) in over_keys:
                continue
            rest.append(abs(u - v) / max(abs(u), abs(v)))
    return {
        "rows": len(ra),
        "largest_relative_change": worst,
        "largest_relative_change_of_the_others": max(rest),
        "over_rtol": over,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before", type=Path)
    ap.add_argument("after", type=Path)
    ap.add_argument("--rtol", type=float, default=1e-9)
    ap.add_argument("--out", type=Path)
    args = ap.parse_args()
    out = {}
    for fa in sorted(args.before.glob("*.json")):
        fb = args.after / fa.name
        if not fb.is_file() or fb.stat().st_size == 0 or fa.stat().st_size == 0:
            out[fa.name] = {"error": "missing"}
            continue
        out[fa.name] = compare(json.loads(fa.read_text()), json.loads(fb.read_text()), args.rtol)
        r = out[fa.name]
        print(
            f"{fa.name}: {r.get('rows')} rows, largest relative change "
            f"{r.get('largest_relative_change', float('nan')):.3g}, of the others "
            f"{r.get('largest_relative_change_of_the_others', float('nan')):.3g}; over rtol: "
            + ", ".join(
                f"{o['quantity']} {o['field']} (|Δ| = {o.get('abs_change', 'null')})"
                for o in r.get("over_rtol", [])
            )
        )
    if args.out:
        args.out.write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
