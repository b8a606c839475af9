"""``--json`` is JSON on every exit path (issue 42): a usage error, a refused input, a command's
own failure each print one JSON object on standard output (``"ok": false``, the exit status and
the same one-line message as on standard error), and the exit status is unchanged."""

import json

import pytest

from hsgeo.cli import main

# every command with --json, given an input file that does not exist (an HsgeoError)
MISSING = {
    "calibrate-line": ["calibrate-line", "{d}/nope.csv", "--control", "{d}/nope2.csv"],
    "calibrate-frame": ["calibrate-frame", "{d}/nope.png", "--board", "{d}/board.toml"],
    "orthorectify": [
        "orthorectify",
        "{d}/nope.nc",
        "--trajectory",
        "{d}/nav.csv",
        "--sensor",
        "{d}/cam.toml",
        "--dsm",
        "{d}/dsm.tif",
        "--resolution",
        "1",
        "-o",
        "{d}/out.tif",
    ],
    "adjust-pushbroom": [
        "adjust-pushbroom",
        "{d}/nope.parquet",
        "--trajectory",
        "{d}/nav.csv",
        "--camera",
        "{d}/cam.toml",
    ],
    "lp-observations": [
        "lp-observations",
        "{d}/nope.nc",
        "--trajectory",
        "{d}/nav.csv",
        "--camera",
        "{d}/cam.toml",
        "-o",
        "{d}/obs.parquet",
    ],
    "adjust-bal": ["adjust-bal", "{d}/nope.txt"],
    "mtf": ["mtf", "{d}/nope.csv", "--bars", "{d}/bars.toml"],
    "mtf-edge": ["mtf-edge", "{d}/nope.png"],
    "cube": ["cube", "{d}/raw", "--dark", "{d}/dark", "-o", "{d}/c.nc"],
    "asf": ["asf", "{d}/cross.nc", "{d}/along.nc", "--runway", "{d}/runway.csv"],
}


def _one_json(text: str) -> dict:
    out = json.loads(text)  # exactly one JSON document, nothing else on stdout
    assert isinstance(out, dict)
    return out


@pytest.mark.parametrize("command", sorted(MISSING))
def test_refused_input_is_json(command, tmp_path, capsys):
    argv = [a.format(d=tmp_path) for a in MISSING[command]] + ["--json"]
    assert main(argv) == 2
    cap = capsys.readouterr()
    out = _one_json(cap.out)
    assert out["ok"] is False and out["exit_status"] == 2 and out["command"] == command
    assert out["error"] in cap.err  # the same line as on standard error
    assert "\n" not in out["error"]


@pytest.mark.parametrize("command", sorted(MISSING))
def test_usage_error_is_json(command, tmp_path, capsys):
    argv = [a.format(d=tmp_path) for a in MISSING[command]] + ["--json", "--no-such-option"]
    with pytest.raises(SystemExit) as e:
        main(argv)
    assert e.value.code == 2
    cap = capsys.readouterr()
    out = _one_json(cap.out)
    assert out["ok"] is False and out["exit_status"] == 2
    assert "--no-such-option" in out["error"] and "--no-such-option" in cap.err


def test_reproduce_bad_scale_is_json(capsys):
    with pytest.raises(SystemExit):
        main(["reproduce", "mtf", "--scale", "small", "--json"])
    out = _one_json(capsys.readouterr().out)
    assert out["command"] == "reproduce" and "(0, 1]" in out["error"]


def test_without_json_stdout_stays_empty(tmp_path, capsys):
    assert main(["mtf-edge", str(tmp_path / "nope.png")]) == 2
    cap = capsys.readouterr()
    assert cap.out == "" and "nope.png" in cap.err


def test_observation_error_of_mtf_edge_is_json(tmp_path, capsys):
    """A refused region (the command's own judgement, not a file error) is JSON too."""
    import numpy as np
    from PIL import Image

    Image.fromarray(np.full((64, 64), 100, np.uint8)).save(tmp_path / "flat.png")
    assert main(["mtf-edge", str(tmp_path / "flat.png"), "--roi", "0,0,64,64", "--json"]) == 2
    out = _one_json(capsys.readouterr().out)
    assert out["ok"] is False and "edge" in out["error"]


# --- every other exit path (issue 42): interrupted, a command's own failure, a bug, poor fit --


def _handler(command: str) -> str:
    return "_cmd_" + command.replace("-", "_")


@pytest.mark.parametrize("command", sorted(MISSING))
@pytest.mark.parametrize(
    "exc, status",
    [
        (KeyboardInterrupt(), 130),  # Ctrl-C
        (SystemError("kernel returned a result with an exception set"), 1),  # a bug
    ],
    ids=["interrupted", "internal-error"],
)
def test_every_exit_path_is_json(command, exc, status, tmp_path, capsys, monkeypatch):
    """The command's handler ends in Ctrl-C, or in an exception hsgeo does not know (a bug,
    which keeps its traceback on standard error): standard output is still one JSON object
    naming the command and the exit status."""
    import hsgeo.cli as cli

    def fail(args):
        raise exc

    monkeypatch.setattr(cli, _handler(command), fail)
    argv = [a.format(d=tmp_path) for a in MISSING[command]] + ["--json"]
    if status == 1:
        with pytest.raises(type(exc)):
            main(argv)
    else:
        assert main(argv) == status
    out = _one_json(capsys.readouterr().out)
    assert out["ok"] is False and out["exit_status"] == status and out["command"] == command


@pytest.mark.parametrize("command", sorted(MISSING))
def test_a_commands_own_refusal_is_json(command, tmp_path, capsys, monkeypatch):
    """An ObservationError or a ConvergenceError raised by the work itself (not by reading the
    files) is JSON too, with the same line as on standard error."""
    import hsgeo.cli as cli
    from hsgeo.errors import ConvergenceError, ObservationError

    argv = [a.format(d=tmp_path) for a in MISSING[command]] + ["--json"]
    for exc in (ObservationError("no edge in the region"), ConvergenceError("diverged")):

        def fail(args, exc=exc):
            raise exc

        monkeypatch.setattr(cli, _handler(command), fail)
        assert main(argv) == 2
        cap = capsys.readouterr()
        out = _one_json(cap.out)
        assert out["ok"] is False and out["exit_status"] == 2
        assert out["error"] in cap.err and "\n" not in out["error"]
