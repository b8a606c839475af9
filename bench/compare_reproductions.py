"""Compare two sets of ``hsgeo reproduce CHAPTER --json`` outputs, row by row (timings aside).

Used for the re-layering's invariance check (issue 11): save the JSON of every chapter before
and after a change that must not change any number, then

    python bench/compare_reproductions.py BEFORE_DIR AFTER_DIR [--out RESULT.json]

prints, per file, the largest relative change of ``paper``, ``paper_sigma``, ``reproduced``,
``sigma`` and ``truth`` over all rows, and every value that moved by more than ``--rtol``
(default 1e-9) with its absolute change. With ``--by-key`` rows are matched by (table,
quantity, unit) instead of by position, so that two versions whose chapters gained or lost rows
can be compared: rows only before or only after are listed, the others compared as above.
"""

import argparse
import json
import math
from pathlib import Path

KEYS = ("paper", "paper_sigma", "reproduced", "sigma", "truth")


def by_key(a: dict, b: dict) -> tuple[dict, dict, dict]:
    """The rows both have, in the same order, and the rows only ``a`` / only ``b`` has."""

    def key(r):
        return (r["table"], r["quantity"], r["unit"])

    ka, kb = {key(r): r for r in a["rows"]}, {key(r): r for r in b["rows"]}
    both = [k for k in ka if k in kb]
    only = (
        [f"{k[0]}: {k[1]}" for k in ka if k not in kb],
        [f"{k[0]}: {k[1]}" for k in kb if k not in ka],
    )
    return {"rows": [ka[k] for k in both]}, {"rows": [kb[k] for k in both]}, only


def compare(a: dict, b: dict, rtol: float, keyed: bool = False) -> dict:
    only = ([], [])
    if keyed:
        a, b, only = by_key(a, b)
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
        **({"only_before": only[0], "only_after": only[1]} if keyed else {}),
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
    ap.add_argument("--by-key", action="store_true", help="match rows by table and quantity")
    args = ap.parse_args()
    out = {}
    for fa in sorted(args.before.glob("*.json")):
        fb = args.after / fa.name
        if not fb.is_file() or fb.stat().st_size == 0 or fa.stat().st_size == 0:
            out[fa.name] = {"error": "missing"}
            continue
        out[fa.name] = compare(
            json.loads(fa.read_text()), json.loads(fb.read_text()), args.rtol, args.by_key
        )
        r = out[fa.name]
        if args.by_key:
            print(
                f"{fa.name}: {len(r['only_before'])} rows only before, "
                f"{len(r['only_after'])} only after"
            )
        print(
            f"{fa.name}: {r.get('rows')} rows in both, largest relative change "
            f"{r.get('largest_relative_change', float('nan')):.3g}, of the others "
            f"{r.get('largest_relative_change_of_the_others', float('nan')):.3g}; over rtol: "
            + ", ".join(
                f"{o['quantity']} {o['field']} (|Δ| = {o.get('abs_change', 'null')})"
                for o in r.get("over_rtol", [])[:8]
            )
            + (f" and {len(r['over_rtol']) - 8} more" if len(r.get("over_rtol", [])) > 8 else "")
        )
    if args.out:
        args.out.write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
