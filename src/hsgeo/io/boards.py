"""Calibration boards (ChArUco or ArUco grid): the description and the board file.

A :class:`Board` gives every length in millimetres, as the board file does (``--board
BOARD.toml`` of ``hsgeo calibrate-frame``, :func:`read_board`)::

    [board]
    type = "charuco"          # or "aruco_grid"
    dictionary = "DICT_6X6_250"
    # charuco: squares and the marker inside a white square, lengths in mm
    squares_x = 5
    squares_y = 7
    square_mm = 40.0
    marker_mm = 20.0
    # aruco_grid instead: markers_x, markers_y, marker_mm, separation_mm (first id 0)

    [camera]                  # optional
    pixel_mm = 0.0055         # pixel pitch; without it the "mm" of the results are pixels

Object coordinates are OpenCV's board frame (x right, y down, z into the board).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from hsgeo.errors import InputError
from hsgeo.io.config import Key, read_dataclass

__all__ = [
    "Board",
    "OPENCV_TUTORIAL_CHARUCO",
    "LENGTH_UNITS_MM",
    "BoardFile",
    "BoardTable",
    "BoardCameraTable",
    "read_board",
    "BOARD_TYPES",
]

#: Length units OpenCV can be given the board in, in mm.
LENGTH_UNITS_MM = {"mm": 1.0, "m": 1000.0}

BOARD_TYPES = ("charuco", "aruco_grid")


@dataclass(frozen=True)
class Board:
    """A planar calibration board, lengths in mm (see the module docstring).

    Build one with :meth:`charuco` or :meth:`aruco_grid`, or read it with
    :func:`hsgeo.io.read_board`.

    Attributes
    ----------
    type : {"charuco", "aruco_grid"}
    dictionary : str
        OpenCV ArUco dictionary name (``DICT_6X6_250``).
    nx, ny : int
        Squares (charuco) or markers (aruco_grid) across and down.
    marker_mm : float
        Side of a marker.
    square_mm : float or None
        Side of a chessboard square (charuco only).
    separation_mm : float or None
        Gap between markers (aruco_grid only).
    pixel_mm : float or None
        Pixel pitch of the camera, if known.
    """

    type: str
    dictionary: str
    nx: int
    ny: int
    marker_mm: float
    square_mm: float | None = None
    separation_mm: float | None = None
    pixel_mm: float | None = None

    def __post_init__(self):
        if self.type not in BOARD_TYPES:
            raise InputError(f"board type must be 'charuco' or 'aruco_grid', got {self.type!r}")
        need = "square_mm" if self.type == "charuco" else "separation_mm"
        if getattr(self, need) is None:
            raise InputError(f"a {self.type} board needs {need}")
        for name in ("marker_mm", need, "pixel_mm"):
            v = getattr(self, name)
            if v is not None and not v > 0:
                raise InputError(f"board {name} must be positive, got {v}")
        if self.type == "charuco" and not self.marker_mm < self.square_mm:
            raise InputError(
                f"marker_mm ({self.marker_mm:g}) must be smaller than square_mm "
                f"({self.square_mm:g}): the marker is printed inside a white square"
            )
        if self.nx < 2 or self.ny < 2:
            raise InputError(
                f"a board needs at least 2 x 2 squares or markers, got {self.nx} x {self.ny} "
                "(squares_x/y or markers_x/y)"
            )

    @classmethod
    def charuco(
        cls,
        squares_x: int,
        squares_y: int,
        square_mm: float,
        marker_mm: float,
        dictionary: str,
        pixel_mm: float | None = None,
    ) -> Board:
        """A ChArUco board of ``squares_x × squares_y`` squares."""
        return cls(
            "charuco",
            dictionary,
            int(squares_x),
            int(squares_y),
            float(marker_mm),
            square_mm=float(square_mm),
            pixel_mm=pixel_mm,
        )

    @classmethod
    def aruco_grid(
        cls,
        markers_x: int,
        markers_y: int,
        marker_mm: float,
        separation_mm: float,
        dictionary: str,
        pixel_mm: float | None = None,
    ) -> Board:
        """A grid of ``markers_x × markers_y`` ArUco markers (first id 0)."""
        return cls(
            "aruco_grid",
            dictionary,
            int(markers_x),
            int(markers_y),
            float(marker_mm),
            separation_mm=float(separation_mm),
            pixel_mm=pixel_mm,
        )

    def cv_board(self, length_unit: str = "mm"):
        """The ``cv2.aruco.CharucoBoard`` or ``GridBoard``, lengths in ``length_unit``.

        ``length_unit`` (``"mm"`` or ``"m"``) is the unit of the object coordinates OpenCV
        returns. OpenCV computes in float32, so the unit changes the last bits of the corners
        (and the ChArUco corner interpolation by ~3e-5 px); give OpenCV the unit of the data
        you compare with.
        """
        import cv2

        if length_unit not in LENGTH_UNITS_MM:
            raise InputError(
                f"length_unit must be one of {list(LENGTH_UNITS_MM)}, got {length_unit!r}"
            )
        if not hasattr(cv2.aruco, self.dictionary):
            raise InputError(f"unknown ArUco dictionary {self.dictionary!r} (e.g. DICT_6X6_250)")
        f = LENGTH_UNITS_MM[length_unit]
        d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary))
        if self.type == "charuco":
            return cv2.aruco.CharucoBoard(
                (self.nx, self.ny), self.square_mm / f, self.marker_mm / f, d
            )
        return cv2.aruco.GridBoard(
            (self.nx, self.ny), self.marker_mm / f, self.separation_mm / f, d
        )


#: The ChArUco board of OpenCV's tutorial images (opencv_contrib aruco tutorial, img_00..03):
#: 5 × 7 squares of 40 mm, 20 mm markers, DICT_6X6_250.
OPENCV_TUTORIAL_CHARUCO = Board.charuco(5, 7, 40.0, 20.0, "DICT_6X6_250")


_CHARUCO = ("squares_x", "squares_y", "square_mm", "marker_mm")
_GRID = ("markers_x", "markers_y", "marker_mm", "separation_mm")


def _key(kind: str, doc: str, **kw):
    return field(default=None, metadata={"key": Key(kind, doc=doc, positive=True, **kw)})


@dataclass(frozen=True, kw_only=True)
class BoardTable:
    """The ``[board]`` table of a board file: the type's keys, lengths in mm (the schema
    :func:`read_board` loads through :func:`hsgeo.io.config.read_dataclass`).
    """

    type: str = field(metadata={"key": Key("str", choices=BOARD_TYPES, doc="board type")})
    dictionary: str = field(
        metadata={"key": Key("str", doc="OpenCV ArUco dictionary, e.g. DICT_6X6_250")}
    )
    squares_x: int | None = _key("int", "charuco: squares across")
    squares_y: int | None = _key("int", "charuco: squares down")
    square_mm: float | None = _key("float", "charuco: square side, mm")
    markers_x: int | None = _key("int", "aruco_grid: markers across")
    markers_y: int | None = _key("int", "aruco_grid: markers down")
    separation_mm: float | None = _key("float", "aruco_grid: gap between markers, mm")
    marker_mm: float | None = _key("float", "marker side, mm")


@dataclass(frozen=True, kw_only=True)
class BoardCameraTable:
    """The optional ``[camera]`` table of a board file."""

    pixel_mm: float | None = _key("float", "pixel pitch, mm", limit=1.0)


@dataclass(frozen=True, kw_only=True)
class BoardFile:
    """The board file: ``[board]`` (keys of its type, lengths in mm) and an optional
    ``[camera]``.
    """

    board: BoardTable
    camera: BoardCameraTable = BoardCameraTable()


def read_board(path) -> Board:
    """Read a board file into a :class:`Board` (lengths in mm).

    Raises
    ------
    InputError
        Missing file, malformed TOML, unknown or misspelled keys, keys of the other board type,
        missing keys of the board's type, an unknown ArUco dictionary.
    """
    import cv2

    path = Path(path)
    f = read_dataclass(path, BoardFile, "board file")
    b = f.board
    keys, other = (_CHARUCO, _GRID) if b.type == "charuco" else (_GRID, _CHARUCO)
    missing = [k for k in keys if getattr(b, k) is None]
    stray = [k for k in other if getattr(b, k) is not None and k not in keys]
    problems = []
    if missing:
        problems.append(f"[board] of type {b.type} is missing {', '.join(missing)}; add them")
    if stray:
        problems.append(
            f"[board] {', '.join(stray)} belong to the other board type; remove them or change type"
        )
    if not hasattr(cv2.aruco, b.dictionary):
        problems.append(
            f"[board] dictionary: unknown ArUco dictionary {b.dictionary!r} (e.g. DICT_6X6_250)"
        )
    if problems:
        raise InputError(f"board file {path}: " + "; ".join(problems))
    make = Board.charuco if b.type == "charuco" else Board.aruco_grid
    try:
        return make(*(getattr(b, k) for k in keys), b.dictionary, f.camera.pixel_mm)
    except InputError as exc:
        raise InputError(f"board file {path}: {exc}; correct [board]") from None
