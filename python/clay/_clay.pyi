"""Type stubs of the native module clay._clay (re-exported by the package clay)."""

import os
from typing import Any, Literal, Mapping, Sequence

import numpy as np
import numpy.typing as npt

__version__: str

#: The names Session(grammar, **solver_settings) accepts (clayc run --set's).
SOLVER_SETTINGS: list[str]

StrPath = str | os.PathLike[str]
#: Any pair of numbers: a tuple, a list, a numpy array of two (numpy's scalars too).
Point = tuple[float, float] | Sequence[float] | npt.ArrayLike
#: A whole number: Python's int or numpy's integers.
Count = int | np.integer[Any]
Compass = Literal["east", "west", "north", "south"]
Overlay = Literal["graph", "sites", "strain", "handles", "states"]

class GrammarError(ValueError):
    """A grammar did not compile.

    The message is the rustc-style rendering ``clayc check`` prints; ``diagnostics`` lists
    every error and warning.
    """

    diagnostics: list[Diagnostic]

class SolverError(RuntimeError):
    """A solver frame failed (the message names the step)."""

class InternalError(RuntimeError):
    """A bug in Clay: the library failed where it should not."""

class ScriptParamsError(ValueError):
    """A script recorded with other grammar parameters than the session's: its gestures
    would grab other parts of this model."""

class Diagnostic:
    """One error or warning about a grammar, as ``clayc check --format json`` gives it."""

    @property
    def code(self) -> str:
        """The stable code (``E011``, ``W001``), listed in docs/language.md."""
    @property
    def severity(self) -> Literal["error", "warning"]: ...
    @property
    def message(self) -> str: ...
    @property
    def path(self) -> str:
        """The file the diagnostic is in: the grammar, or a file it imports."""
    @property
    def line(self) -> int:
        """1-based line where it starts."""
    @property
    def column(self) -> int:
        """1-based column (in characters) where it starts."""
    @property
    def end_line(self) -> int: ...
    @property
    def end_column(self) -> int: ...
    @property
    def hints(self) -> list[str]:
        """What to do about it (``did you mean `brick`?``)."""

def check(path: StrPath) -> list[Diagnostic]:
    """Compiles the grammar at ``path`` and returns its diagnostics (errors and warnings) in
    file order; an empty list when it is clean. Raises OSError when it cannot be read."""

ParamValue = float | int | bool | str
"""A parameter's value: ``float`` for a number, ``int`` for an ``int`` or ``seed``, ``bool``,
and ``str`` (a piece's name) for a ``choice``."""

class Param:
    """A grammar parameter: its type, its value in this compilation, its default and range."""

    @property
    def name(self) -> str: ...
    @property
    def kind(self) -> Literal["number", "int", "bool", "seed", "choice"]: ...
    @property
    def value(self) -> ParamValue: ...
    @property
    def default(self) -> ParamValue: ...
    @property
    def range(self) -> tuple[float, float] | None: ...
    @property
    def choices(self) -> list[str] | None:
        """A ``choice``'s pieces, in order; ``None`` for another type."""

class Piece:
    """A piece of a grammar, its rest states, vertices and docking sites by name."""

    @property
    def name(self) -> str: ...
    @property
    def states(self) -> list[str]: ...
    @property
    def vertices(self) -> list[str]: ...
    @property
    def sites(self) -> list[str]: ...

class Grammar:
    """A compiled grammar. Errors raise GrammarError; warnings are kept in ``warnings``."""

    @staticmethod
    def open(path: StrPath, params: Mapping[str, ParamValue] | None = None) -> Grammar:
        """Reads and compiles the grammar at ``path`` (imports are found beside it).

        Raises OSError (unreadable file), GrammarError (errors in the grammar, an unknown
        parameter, a value outside its range, a choice it does not list), TypeError (a value
        of another type than its parameter's: a str for a number, 2.5 for an ``int``)."""
    @staticmethod
    def parse(
        text: str,
        path: StrPath | None = None,
        params: Mapping[str, ParamValue] | None = None,
    ) -> Grammar:
        """Compiles grammar text; ``path`` names it in diagnostics and locates its imports."""
    @property
    def path(self) -> str | None: ...
    @property
    def warnings(self) -> list[Diagnostic]: ...
    @property
    def params(self) -> list[Param]: ...
    @property
    def pieces(self) -> list[Piece]: ...
    @property
    def instance_count(self) -> int:
        """How many instances the model starts with."""
    @property
    def solver(self) -> dict[str, float]:
        """The ``solver`` block: hysteresis, norm, irls_epsilon, merge_distance."""

class Instance:
    """One instance of a piece in a session's model."""

    @property
    def id(self) -> int:
        """Stable identity: survives the rules that keep the instance."""
    @property
    def name(self) -> str:
        """``wall[3]`` from the model, ``wall#12`` for an inserted element."""
    @property
    def piece(self) -> str: ...
    @property
    def state(self) -> str:
        """The active rest state's name."""
    @property
    def chain(self) -> str | None:
        """The stretch chain it is an element of, named as every export names it (``wall_n``), or None."""
    @property
    def index(self) -> int | None:
        """Its place in that chain (0 first), or None."""
    @property
    def vertices(self) -> list[int]:
        """Rows of Session.positions, one per piece vertex."""
    @property
    def centroid(self) -> tuple[float, float]: ...

class RuleEvent:
    """A rule that fired."""

    @property
    def kind(self) -> Literal["replace", "stretch", "shrink", "merge", "cut"]: ...
    @property
    def frame(self) -> int: ...
    @property
    def at(self) -> tuple[float, float]: ...
    @property
    def instances(self) -> list[int]:
        """Stable ids of the instances involved."""
    @property
    def detail(self) -> str:
        """A sentence in the grammar's names."""

class Primitive:
    """Triangles of one colour of one instance: metres, z up (x east, y north)."""

    @property
    def colour(self) -> tuple[int, int, int, int]:
        """sRGB bytes (r, g, b, a)."""
    @property
    def material(self) -> str:
        """Its material's name in every export and the Blender add-on (``fill_9a958cff``)."""
    @property
    def positions(self) -> npt.NDArray[np.float32]:
        """Shape (n, 3)."""
    @property
    def triangles(self) -> npt.NDArray[np.uint32]:
        """Shape (m, 3), counter-clockwise seen from outside."""
    @property
    def uvs(self) -> npt.NDArray[np.float32]:
        """Shape (n, 2): planar texture coordinates in metres, v up, one per position."""

class SceneNode:
    """One instance's 3D meshes as ``clayc export`` writes its node: name, pivot, turn, mesh."""

    @property
    def name(self) -> str: ...
    @property
    def piece(self) -> str: ...
    @property
    def state(self) -> str: ...
    @property
    def id(self) -> int: ...
    @property
    def instance(self) -> str:
        """The instance's name in the model (``wall[3]``), as ``Session.instances`` has it."""
    @property
    def chain(self) -> str | None:
        """The stretch chain's name in the export (``wall_n``), or None."""
    @property
    def index(self) -> int | None:
        """The instance's place in its chain (0 at its ``from`` end), or None."""
    @property
    def pivot(self) -> tuple[float, float]:
        """Where the node stands (x, y), metres: the centroid of the instance's vertices."""
    @property
    def rotation(self) -> float:
        """The node's turn about the vertical, radians, counter-clockwise from above."""
    @property
    def mesh(self) -> str | None:
        """The shared mesh's name (``brick__rest``); nodes with one mesh have equal primitives."""
    @property
    def primitives(self) -> list[Primitive]:
        """In the node's frame: a point ``p`` is at ``pivot + R(rotation) p[:2]``, height ``p[2]``."""

class Session:
    """A sculpting session on a grammar's model; the script vocabulary as methods.

    ``solver_settings`` are ``clayc run --set``'s: hysteresis, norm, irls_epsilon,
    merge_distance, irls_iterations, l2_iterations, l2_anderson, handle_weight (numbers) and
    solver ("cholesky" or "cg"). A bad name or value raises ValueError.
    """

    def __init__(self, grammar: Grammar, **solver_settings: float | str) -> None: ...
    def grab(self, at: Point | None = None, extreme: Compass | None = None) -> None:
        """Makes the instance nearest ``at`` (or reaching furthest ``extreme``) the grab."""
    def pin(self, at: Point | None = None, extreme: Compass | None = None) -> None:
        """Pins the selected instance where it is."""
    def unpin(self, at: Point | None = None, extreme: Compass | None = None) -> None:
        """Lets go of the pin on the selected instance."""
    def drag(
        self, by: Point | None = None, to: Point | None = None, frames: Count = 1
    ) -> None:
        """Moves the grab by an offset, or its centroid to a point, over ``frames`` frames."""
    def rotate(self, degrees: float, frames: Count = 1) -> None:
        """Turns the grab about its centroid over ``frames`` frames."""
    def hold(self, frames: Count = 1) -> None:
        """Runs frames without moving anything."""
    def release(self) -> None:
        """Lets go of the grab."""
    def cut(self, at: Point) -> None:
        """Cuts the connection nearest ``at``."""
    def frame(self) -> list[RuleEvent]:
        """Runs one frame; returns the rules that fired in it."""
    def run_script(self, script: StrPath | Mapping[str, Any]) -> None:
        """Runs a script file or a script dict ``{"steps": [...]}`` (docs/scripts.md)."""
    def summary(self) -> dict[str, Any]:
        """The dict ``clayc run --json`` prints."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """Every vertex position, shape (vertices, 2), a copy."""
    @property
    def instances(self) -> list[Instance]: ...
    @property
    def rule_log(self) -> list[RuleEvent]: ...
    @property
    def notes(self) -> list[str]:
        """Why steps did nothing, as ``clayc run`` prints them."""
    @property
    def frames(self) -> int:
        """Solver frames run so far."""
    @property
    def solver(self) -> dict[str, float]:
        """The grammar's solver block with this session's settings."""
    def export(self, path: StrPath, thickness: float | None = None) -> None:
        """Writes .glb, .gltf, .obj (+ .mtl) or .usda (USD, Z up) as ``clayc export`` does, or
        .usdc (USD's binary form) through usd-core's ``pxr`` (ValueError when not installed)."""
    def render_png(
        self,
        size: tuple[int, int] = (1024, 768),
        overlays: Sequence[Overlay] | None = None,
        view: Literal["plan", "iso"] = "plan",
    ) -> bytes:
        """The model drawn as ``clayc render`` draws it, as PNG bytes."""
    def scene(self, thickness: float | None = None) -> list[SceneNode]:
        """The 3D meshes ``clayc export`` writes, one node per instance."""
