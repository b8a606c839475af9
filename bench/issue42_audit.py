"""Issue 42's done-means lines measured on this branch: ``bench/results/issue42_audit.json``.

    python bench/issue42_audit.py [--junit FILE ...]

One entry per done-means line: the line, ``status`` (met / short / not-measured) and the
evidence (files, test ids, computed numbers). Computed here: the README's command lines against
those ``.ci/check_wheel.sh`` runs (subcommand, options and the kind of each value) and the last
``make check-wheel`` log (``bench/results/check_wheel.log``: this script, run to its end); the
seed sweep's counts (``bench/results/seed_sweep.json``);
``mtf-edge`` over every region of a masked target (``tests/test_bad_input_mtf_edge.py``'s
sweep); every subcommand of the parser on every exit path with ``--json`` (in this process,
each handler replaced by one that fails); the bad-input suite's cases and classes
(``tests/test_bad_input.py``, ``tests/test_bad_input_classes.py``) and what each case did in
the last run (``bench/results/bad_input_cases.jsonl``, written by the suite with
``HSGEO_BAD_INPUT_RECORD``). ``--junit`` reads pytest JUnit reports of the suite's runs for
their pass / fail counts.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import re
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
sys.path.insert(0, str(ROOT / "tests"))
SIX = ("cube", "mtf", "mtf-edge", "lp-observations", "orthorectify", "asf")


def _hsgeo_lines(text: str) -> list[str]:
    """The ``hsgeo ...`` command lines of a text (continuations joined, comments dropped; in a
    shell script the commands that must succeed: ``step``, ``json`` and ``"$HS"`` lines, not
    the ``if "$HS" ...`` of a refusal or an ``echo``)."""
    text = re.sub(r"\\\n\s*", " ", text)
    out = []
    for line in text.splitlines():
        m = re.search(r'(?:\.venv/bin/hsgeo|"?\$HS"?|step|json)\s+([a-z][a-z-]+)(.*)', line)
        before = line.split(m.group(0))[0] if m else ""
        if m and "#" not in before and not re.search(r"\b(if|echo)\b", before):
            out.append((m.group(1) + m.group(2)).split(" #")[0].strip())
    return out


def _signature(cmd: str) -> set[str]:
    """What a command line exercises: its subcommand, its options (``--x=v`` as ``--x``), the
    kind of each value (a file's suffix: ``--trajectory:.sbet``, ``-o:.tif``; a word such as
    ``--vertical:EPSG:5773`` or ``--mosaic:nearest-nadir``; numbers left out) and of each
    positional argument (``.nc``, ``.raw``, a chapter's name); ``--json``, ``--seed`` and
    ``--scale`` left out (the check runs the chapters smaller)."""
    toks = [t.strip("\"'()") for t in cmd.replace("=", " ").split()]
    sig, opt = {toks[0]}, None
    for t in toks[1:]:
        if t.startswith("-") and not re.fullmatch(r"-[\d.,]+", t):
            opt = None if t in ("--json", "--seed", "--scale") else t
            if opt:
                sig.add(opt)
            continue
        suffix = re.search(r"\.[A-Za-z][A-Za-z0-9]*$", t)
        if suffix and not t.startswith("EPSG:"):
            kind = suffix.group(0).lower()
        elif re.search(r"[A-Za-z]", t) and "/" not in t and not t.startswith("$"):
            kind = t  # a mode word (nearest-nadir, EPSG:5773, ellipsoidal, a chapter)
        else:
            kind = None  # a number, a folder, a placeholder (RAW_DIR, IMAGES...)
        if kind and not ((t.isupper() and not t.startswith("EPSG:")) or t.endswith("...")):
            sig.add(f"{opt}:{kind}" if opt else kind)
        opt = None
    return sig


def _check_wheel_run(script: str) -> dict:
    """The last ``make check-wheel`` output kept in ``bench/results/check_wheel.log``: the
    steps it ran, whether it reached its last line, and whether it ran this check_wheel.sh."""
    import hashlib

    log = RESULTS / "check_wheel.log"
    if not log.exists():
        return {"log": None, "passed_with_this_script": False}
    text = log.read_text(encoding="utf-8", errors="replace")
    sha_now = hashlib.sha256(script.encode()).hexdigest()[:16]
    m = re.search(r"check-wheel: (\S+), \.ci/check_wheel\.sh sha256 ([0-9a-f]+)", text)
    done = re.search(r"check-wheel: the installed wheel ran every command.*\((\d+) s\)", text)
    steps = re.findall(r"^\+ hsgeo (.*)$", text, flags=re.M)
    return {
        "log": str(log.relative_to(ROOT)),
        "wheel": m.group(1) if m else None,
        "script_sha256_16_run": m.group(2) if m else None,
        "script_sha256_16_now": sha_now,
        "steps_run": len(steps),
        "subcommands_run": sorted({s.split()[0] for s in steps if not s.startswith("-")}),
        "reached_the_end": bool(done),
        "duration_s": int(done.group(1)) if done else None,
        "passed_with_this_script": bool(done) and bool(m) and m.group(2) == sha_now,
    }


def wheel() -> dict:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    block = readme.split("## The command line", 1)[1].split("```", 2)[1]
    ci = (ROOT / ".ci" / "check_wheel.sh").read_text(encoding="utf-8")
    ran = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    readme_cmds = _hsgeo_lines(block)
    ci_cmds = _hsgeo_lines(ci)

    uncovered = []
    for c in readme_cmds:
        if not any(_signature(c) <= _signature(x) for x in ci_cmds):
            missing = min((_signature(c) - _signature(x) for x in ci_cmds), key=len)
            uncovered.append({"readme": c, "closest_check_wheel_step_lacks": sorted(missing)})
    subs = sorted({c.split()[0] for c in readme_cmds})
    run = _check_wheel_run(ci)
    ok = not uncovered and "make check-wheel" in ran and run.get("passed_with_this_script")
    return {
        "line": "The wheel, installed alone into a fresh venv, runs every README command from "
        "an empty folder (CI does it)",
        "status": "met" if ok else "short",
        "evidence": {
            "how_ci_checks": ".ci/run (CI's entry) runs `make check-wheel` after make test and "
            "make check-book; .ci/check_wheel.sh builds a fresh venv, pip-installs "
            "dist/hsgeo-*.whl alone (dependencies from the index, -c requirements.lock), cd's "
            "into an empty folder, writes inputs with the installed hsgeo (.ci/wheel_inputs.py) "
            "and runs each command (set -e: the first failure stops it; --json outputs parsed)",
            "ci_runs_check_wheel": "make check-wheel" in ran,
            "readme_command_lines": len(readme_cmds),
            "readme_subcommands": subs,
            "check_wheel_subcommands": sorted({c.split()[0] for c in ci_cmds}),
            "readme_lines_without_a_check_wheel_step_of_their_options": uncovered,
            "tests": "tests/test_packaging.py::test_every_third_party_import_is_a_declared_"
            "dependency, ::test_the_wheel_carries_the_scenarios_and_instruments, "
            "::test_scenarios_found_in_the_package_outside_the_repository",
            "last_run": run,
        },
    }


def seeds() -> dict:
    d = json.loads((RESULTS / "seed_sweep.json").read_text(encoding="utf-8"))
    from hsgeo.reproduce import CHAPTERS

    names = [c for c in CHAPTERS if c != "scoreboard"]
    per = {}
    for c in names:
        v = d.get("chapters", {}).get(c, {})
        done = v.get("seeds_by_scale", {}).get("0.05", [])
        per[c] = {
            "seeds_done_at_0.05": len(done),
            "failed": v.get("failed", 0),
            "failures": v.get("failures", []),
            "commits": v.get("commits", {}),
        }
    fails = sum(p["failed"] for p in per.values())
    ok = fails == 0 and all(p["seeds_done_at_0.05"] >= 50 for p in per.values())
    smallest = {}
    f = RESULTS / "smallest_scale.json"
    if f.exists():
        smallest = json.loads(f.read_text(encoding="utf-8"))
    return {
        "line": "0 chapters fail over 50 seeds at the smallest scale",
        "status": "met" if ok else "short",
        "evidence": {
            "file": "bench/results/seed_sweep.json (bench/bench_seed_sweep.py, resumable per "
            "chapter and seed; nice -n 15)",
            "n_runs": len(d.get("runs", [])),
            "n_failed": fails,
            "per_chapter": per,
            "smallest_scale": "0.05 for every chapter: below it no chapter gets smaller (each "
            "clamps scale to its floor, LP refuses < MIN_SCALE = 0.05)",
            "what_the_knob_reaches": smallest.get("knobs"),
            "profiles_at_0.05": smallest.get("chapters"),
            "why_short": "the sweep costs about 400 CPU-s a seed for the nine chapters in one "
            "warm process (lp-observations, rikola, pushbroom-ba ≈ 95–126 each); the shared "
            "2-core machine (load 10–20) gave a fraction of that; the sweep continues from "
            "where it stopped (same command)",
        },
    }


def mtf_edge() -> dict:
    from test_bad_input_mtf_edge import region_sweep

    sweeps = {str(n): region_sweep(n) for n in (5.0, 0.0)}
    fill = sum(len(s["fill_measured"]) for s in sweeps.values())
    bugs = sum(len(s["not_hsgeo_errors"]) for s in sweeps.values())
    fwhm = min(s["min_fwhm_px"] for s in sweeps.values())
    ok = fill == 0 and bugs == 0 and fwhm >= 1.0
    return {
        "line": "`mtf-edge` never returns an LSF narrower than a pixel and refuses a region "
        "touching fill",
        "status": "met" if ok else "short",
        "evidence": {
            "sweep": "every region of a 200×200 masked target chip (tests/edge_reference.py, an "
            "independent generator) on a 10-px grid of corners, 16–64 × 32–128 px, noisy "
            "(σ 5 DN) and noise-free",
            "per_noise": {
                k: {
                    "regions": s["regions"],
                    "touching_fill": s["touching_fill"],
                    "touching_fill_measured": len(s["fill_measured"]),
                    "clean": s["clean"],
                    "clean_measured": s["clean_measured"],
                    "min_lsf_fwhm_px_of_a_measured_region": s["min_fwhm_px"],
                    "errors_not_hsgeo": len(s["not_hsgeo_errors"]),
                }
                for k, s in sweeps.items()
            },
            "before_this_branch": "38 regions touching the fill were measured (1–32 px of fill "
            "in a corner or beyond the ESF's window) and 12 ended in an IndexError",
            "code": "src/hsgeo/measure/edge.py: slanted_edge refuses an LSF FWHM < "
            "MIN_LSF_FWHM_PX = 1 (NaN too); check_region refuses any pixel below the dark or "
            "above the bright plateau, blocks of one value, pixels off the ESF",
            "tests": "tests/test_bad_input_mtf_edge.py::test_every_region_touching_fill_is_"
            "refused (slow), ::test_regions_touching_fill_found_by_the_sweep, "
            "::test_a_dead_pixel_is_named; tests/test_measure_mtf.py::test_lsf_narrower_than_a_"
            "pixel_is_refused, ::test_region_reaching_the_fill_is_refused, "
            "::test_narrow_valid_regions_are_measured, ::test_masked_target_chip_found_without_"
            "roi; tests/test_cli_json.py::test_observation_error_of_mtf_edge_is_json",
        },
    }


def json_paths() -> dict:
    import errno

    import test_bad_input as B
    import test_bad_input_every_command as T

    import hsgeo.cli as cli
    import hsgeo.errors as E

    kinds = {
        "interrupted": (KeyboardInterrupt(), 130),
        "input": (E.InputError("x"), 2),
        "observation": (E.ObservationError("x"), 2),
        "datum": (E.DatumError("x"), 2),
        "convergence": (E.ConvergenceError("x"), 2),
        "memory": (MemoryError(), 2),
        "disk-full": (OSError(errno.ENOSPC, "No space left on device"), 2),
        "bug": (RuntimeError("x"), 1),
    }
    tally: Counter = Counter()
    not_json = []
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        for cmd in T.COMMANDS:
            paths = []
            if T.has_json(cmd):
                for name, (exc, status) in kinds.items():
                    paths.append((name, T._parsable_argv(cmd, d), exc, status))
            paths.append(("usage", [cmd, "--json", "--no-such-option"], None, 2))
            paths.append(("help", [cmd, "--help", "--json"], None, 0))
            for name, argv, exc, status in paths:
                handler = T._handler(cmd)
                real = getattr(cli, handler)
                if exc is not None:

                    def fail(args, exc=exc):
                        raise exc

                    setattr(cli, handler, fail)
                out, err = io.StringIO(), io.StringIO()
                try:
                    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                        try:
                            rc = cli.main(argv)
                        except SystemExit as e:
                            rc = e.code or 0
                        except RuntimeError:
                            rc = 1
                finally:
                    setattr(cli, handler, real)
                try:
                    doc = json.loads(out.getvalue())
                    good = isinstance(doc, dict) and doc.get("exit_status") == status == rc
                except json.JSONDecodeError:
                    good = False
                tally[name] += 1
                if not good:
                    not_json.append((cmd, name, rc, out.getvalue()[:200]))
        _ = B  # the suite's valid command lines (base_argv) are the argv above
    return {
        "line": "`--json` is JSON on every exit path",
        "status": "met" if not not_json else "short",
        "evidence": {
            "subcommands_from_the_parser": T.COMMANDS,
            "with_json_option": [c for c in T.COMMANDS if T.has_json(c)],
            "without_json_option": [c for c in T.COMMANDS if not T.has_json(c)],
            "exit_paths_run_here": dict(tally),
            "n_runs": sum(tally.values()),
            "not_one_json_object_with_its_exit_status": not_json,
            "not_covered": "a closed standard output (exit 141: nothing can be printed); "
            "`versions` and `data` have no --json: asked for it, they refuse it with a JSON "
            "usage error",
            "tests": "tests/test_bad_input_every_command.py::test_bad_input_of_every_command "
            "(every subcommand and orthorectify's four inputs, --json and text), "
            "::test_every_exit_path_of_every_command_is_json, ::test_usage_error_of_every_"
            "command_is_json, ::test_help_and_version_with_json_are_json, ::test_interrupted_"
            "before_the_parser_is_json, ::test_exit_0_of_every_command_is_json (slow); "
            "tests/test_cli_json.py; tests/test_bad_input.py::test_bad_input (every case with "
            "--json parses)",
        },
    }


def _junit(files) -> dict:
    out = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0, "failed_ids": [], "skips": {}}
    for f in files:
        root = ET.parse(f).getroot()
        for ts in root.iter("testsuite"):
            for k in ("tests", "failures", "errors", "skipped"):
                out[k] += int(ts.get(k, 0))
        for tc in root.iter("testcase"):
            if tc.find("failure") is not None or tc.find("error") is not None:
                out["failed_ids"].append(f"{tc.get('classname')}::{tc.get('name')}")
            if tc.find("skipped") is not None:
                out["skips"][tc.get("name")] = tc.find("skipped").get("message", "")
    return out


def _case_records(cases) -> dict:
    """Counts over ``bench/results/bad_input_cases.jsonl``: one line per case of
    ``tests/test_bad_input.py::test_bad_input`` written by the run (``HSGEO_BAD_INPUT_RECORD``):
    its exit status and, whichever assertion failed first, a traceback (or exit 1), an exit 0
    (an answer on bad input), its inputs changed, its outputs or ``*.part`` files left."""
    f = RESULTS / "bad_input_cases.jsonl"
    if not f.exists():
        return {"file": None, "cases_run": 0}
    rows = {}
    for line in f.read_text(encoding="utf-8").splitlines():
        r = json.loads(line)
        rows[r["id"]] = r  # a case run twice: its last run
    ids = {c.id for c in cases}
    rs = [r for i, r in rows.items() if i in ids]
    not_run = sorted(ids - set(rows))

    def which(key):
        return sorted(r["id"] for r in rs if r[key])

    out = {
        "file": str(f.relative_to(ROOT)),
        "cases": len(ids),
        "cases_run": len(rs),
        "not_run": not_run,
        "exit_status": dict(sorted(Counter(str(r["exit"]) for r in rs).items())),
        "tracebacks": len(which("traceback")),
        "silent_wrong_answers": len(which("answer")),
        "inputs_modified": len(which("inputs_modified")),
        "partial_outputs_left": len(which("partial_outputs")),
        "case_folder_changed": len(which("folder_changed")),
        "not_one_line_on_stderr": sum(not r["one_line"] for r in rs),
        "cause_not_named": sum(not r["cause_named"] for r in rs),
    }
    out["ids"] = {
        k: which(k) for k in ("traceback", "answer", "inputs_modified", "partial_outputs")
    }
    out["ids"]["not_one_line"] = sorted(r["id"] for r in rs if not r["one_line"])
    out["ids"]["cause_not_named"] = sorted(r["id"] for r in rs if not r["cause_named"])
    return out


def _unexplained(rec: dict, runs: dict | None) -> list:
    """Cases without a record that the JUnit report does not show skipped (with its reason)."""
    skips = (runs or {}).get("skips", {})
    return [i for i in rec.get("not_run", []) if f"test_bad_input[{i}]" not in skips]


def bad_input(junit) -> dict:
    import test_bad_input as B
    import test_bad_input_classes as K

    by_cmd = Counter("orthorectify" if c.cmd.startswith("orthorectify") else c.cmd for c in B.CASES)
    kinds_six = {
        s: sorted({c.kind for c in B.CASES if c.cmd.startswith(s) and c.cmd != "mtf-edge" or (
            s == "mtf-edge" and c.cmd == s)})
        for s in SIX
    }  # fmt: skip
    status = Counter(c[3] for c in K.CLASSES)
    open_rows = [(c[0], c[1], c[4][:160]) for c in K.CLASSES if c[3] == "open"]
    silent_open = [r for r in open_rows if r[0].startswith("answer")]
    runs = _junit(junit) if junit else None
    rec = _case_records(B.CASES)
    zero = ("tracebacks", "silent_wrong_answers", "inputs_modified", "partial_outputs_left")
    ok = (
        not silent_open
        and runs is not None
        and not runs["failed_ids"]
        and all(rec.get(k) == 0 for k in zero)
        and not _unexplained(rec, runs)
    )
    short = []
    if silent_open:
        short.append(f"{len(silent_open)} open class(es) answer on wrong input")
    if runs is None:
        short.append("no JUnit report of the suite given (--junit)")
    elif runs["failed_ids"]:
        short.append(f"{len(runs['failed_ids'])} test(s) of the suite failed")
    if runs is not None and _unexplained(rec, runs):
        short.append(f"{len(_unexplained(rec, runs))} case(s) neither recorded nor skipped")
    short += [f"{rec[k]} {k.replace('_', ' ')}" for k in zero if rec.get(k)]
    if rec["file"] is None:
        short.append("no per-case records (run the suite with HSGEO_BAD_INPUT_RECORD)")
    return {
        "line": "the bad-input suite covers the six commands' failure kinds, with 0 tracebacks, "
        "0 silent wrong answers, 0 inputs modified, 0 partial outputs left",
        "status": "met" if ok else "short",
        "evidence": {
            "cases": len(B.CASES),
            "cases_by_command": dict(sorted(by_cmd.items())),
            "kinds_of_the_six_commands": kinds_six,
            "benign_variants": len(B.BENIGN),
            "issue_classes": len(K.CLASSES),
            "issue_classes_by_status": dict(status),
            "open_classes": open_rows,
            "silent_wrong_answers_open": len(silent_open),
            "each_case_asserts": "exit 2, one line on stderr naming the cause, no traceback, "
            "stdout empty (or one JSON object with --json), the SHA-256 of every input "
            "unchanged, no output named by -o/--output/--envi and no *.part left, and (this "
            "branch) the case's whole folder byte-identical afterwards",
            "enumerated_over_commands": "tests/test_bad_input_every_command.py: every "
            "subcommand of the parser with a missing input (the folder byte-identical), an "
            "existing output kept, and the k-th output rename refused for every k of every "
            "writing command (cube, data flight, lp-observations, orthorectify × 4): no partial "
            "set of outputs (io.output_group; before: 'lines.raw.hdr' left by data flight)",
            "suite_runs": runs,
            "case_records": rec,
            "not_run_skipped_by_the_suite": {
                i: (runs or {}).get("skips", {}).get(f"test_bad_input[{i}]")
                for i in rec.get("not_run", [])
            },
            "why_short": "; ".join(short) or None,
        },
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--junit", type=Path, nargs="*", default=[])
    ap.add_argument("--out", type=Path, default=RESULTS / "issue42_audit.json")
    args = ap.parse_args()
    from bench_seed_sweep import code_commit

    entries = [wheel(), seeds(), mtf_edge(), json_paths(), bad_input(args.junit)]
    out = {
        "what": "issue 42's done-means lines measured on this branch",
        "commit": code_commit(),
        "command": "python bench/issue42_audit.py"
        + (" --junit " + " ".join(map(str, args.junit)) if args.junit else ""),
        "summary": {
            s: sum(e["status"] == s for e in entries) for s in ("met", "short", "not-measured")
        },
        "entries": entries,
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    args.out.write_text(json.dumps(out, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(json.dumps(out["summary"]))
    for e in entries:
        print(e["status"], "|", e["line"][:90])


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT / "bench"))
    main()
