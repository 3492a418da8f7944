"""Clay from Python: structured-shape grammars, sculpted headlessly.

Compile a grammar, sculpt its model with the script vocabulary of ``clayc run`` (grab, pin,
drag, rotate, hold, release, cut), read what the session made (summary, positions,
instances, rule log) and write it out (glTF/OBJ export, PNG pictures). A thin binding over
the Rust library: no subprocess. See docs/python.md.

>>> import clay
>>> session = clay.Session(clay.Grammar.open("grammars/wall.clay"))
>>> session.pin(extreme="west")
>>> session.grab(extreme="east")
>>> session.drag(by=(8.0, 0.0), frames=100)
>>> session.summary()["pieces"]
{'brick': 16}
"""

from ._clay import (
    SOLVER_SETTINGS,
    Diagnostic,
    Grammar,
    GrammarError,
    Instance,
    InternalError,
    Param,
    Piece,
    Primitive,
    RuleEvent,
    SceneNode,
    ScriptParamsError,
    Session,
    SolverError,
    __version__,
    check,
)

__all__ = [
    "SOLVER_SETTINGS",
    "Diagnostic",
    "Grammar",
    "GrammarError",
    "Instance",
    "InternalError",
    "Param",
    "Piece",
    "Primitive",
    "RuleEvent",
    "SceneNode",
    "ScriptParamsError",
    "Session",
    "SolverError",
    "__version__",
    "check",
]
