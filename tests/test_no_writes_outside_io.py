"""Only ``hsgeo.io`` writes files (GUIDE §2): an AST scan of every other module of the package
for the calls that write (``open(..., "w"/"a"/"x"/"+")``, ``Path.write_text``/``write_bytes``,
``np.save``/``savez``/``savetxt``, ``to_csv``/``to_parquet``/``to_netcdf``, ``savefig``, ``mkdir``
…). Writers are functions of ``hsgeo.io`` that the others call."""

import ast
from pathlib import Path

import hsgeo

PACKAGE = Path(hsgeo.__file__).parent
#: Method calls that write a file or create a folder.
WRITING_METHODS = {
    "write_text",
    "write_bytes",
    "save",
    "savez",
    "savez_compressed",
    "savetxt",
    "tofile",
    "to_csv",
    "to_parquet",
    "to_netcdf",
    "to_zarr",
    "to_excel",
    "to_hdf",
    "savefig",
    "imwrite",
    "mkdir",
    "makedirs",
    "touch",
    "copyfile",
    "copy2",
    "copytree",
}
WRITE_MODES = set("wax+")


def _mode(call: ast.Call, first_arg: int):
    mode = None
    if len(call.args) > first_arg and isinstance(call.args[first_arg], ast.Constant):
        mode = call.args[first_arg].value
    for k in call.keywords:
        if k.arg == "mode" and isinstance(k.value, ast.Constant):
            mode = k.value.value
    return mode if isinstance(mode, str) else None


def writes_in(source: str) -> list[tuple[int, str]]:
    """(line, call) of every call in ``source`` that writes a file."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.Call):
            continue
        fn = node.func
        if isinstance(fn, ast.Name) and fn.id == "open":
            mode = _mode(node, 1)
        elif isinstance(fn, ast.Attribute) and fn.attr == "open":
            mode = _mode(node, 0)  # Path.open(mode)
        elif isinstance(fn, ast.Attribute) and fn.attr in WRITING_METHODS:
            found.append((node.lineno, fn.attr))
            continue
        else:
            continue
        if mode and WRITE_MODES & set(mode):
            found.append((node.lineno, f"open({mode!r})"))
    return found


def test_the_scan_finds_writers():
    src = (
        "import numpy as np\nopen('a', 'w')\nPath('b').open('a')\np.write_text('x')\n"
        "np.savetxt('c', x)\ndf.to_csv('d')\nfig.savefig('e')\nopen('f')\nPath('g').open()\n"
    )
    assert [line for line, _ in writes_in(src)] == [2, 3, 4, 5, 6, 7]


def test_only_io_writes_files():
    offenders = []
    for f in sorted(PACKAGE.rglob("*.py")):
        rel = f.relative_to(PACKAGE)
        if rel.parts[0] == "io":
            continue
        offenders += [f"{rel}:{line} {call}" for line, call in writes_in(f.read_text())]
    assert not offenders, "files written outside hsgeo.io (use a writer of hsgeo.io):\n" + (
        "\n".join(offenders)
    )
