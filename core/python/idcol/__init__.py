"""iDCOL: implicit differentiable collision detection.

The compiled module is idcol._idcol; everything is re-exported here (see
help(idcol._idcol) for the conventions: frames, twists, units).
"""
import sys as _sys

try:
    import numpy as _numpy  # noqa: F401  (the extension needs it at every call)
except ImportError as _e:  # pragma: no cover - depends on the interpreter
    raise ImportError(
        "idcol needs NumPy, which this interpreter (%s, Python %d.%d) cannot import: %s. "
        "Install numpy for it, or run the interpreter idcol was built for."
        % (_sys.executable, _sys.version_info[0], _sys.version_info[1], _e)) from _e

try:
    from . import _idcol
except ImportError as _e:  # pragma: no cover - depends on the interpreter
    import glob as _glob
    import os as _os
    _built = [_os.path.basename(f) for f in _glob.glob(_os.path.join(_os.path.dirname(__file__), "_idcol*"))]
    raise ImportError(
        "idcol's compiled part cannot be loaded by this interpreter (%s, Python %d.%d): %s. The package holds %s; "
        "it was built for the interpreter named in that file name (cpython-3XY): run that one, or rebuild with "
        "this one (pip install . from the checkout)."
        % (_sys.executable, _sys.version_info[0], _sys.version_info[1], _e, _built or "no _idcol extension")) from _e
from ._idcol import *  # noqa: F401,F403
from ._idcol import __version__  # noqa: F401

__doc__ = _idcol.__doc__

# Classes report (and pickle) as idcol.X, the name users import them by.
for _name in dir(_idcol):
    _obj = getattr(_idcol, _name)
    if isinstance(_obj, type) and getattr(_obj, "__module__", None) == "idcol._idcol":
        try:
            _obj.__module__ = "idcol"
        except (AttributeError, TypeError):  # pragma: no cover
            pass
del _name, _obj


# Pickle reconstructors, importable by name (a compiled function is not).
def _restore_solve_result(state, layout=None):
    # layout: only in the raw-memory pickles of earlier builds, which are refused.
    return _idcol._solve_result(state, layout)


def _restore_batch_result(state):
    return _idcol._batch_result(state)


def _restore_toi_result(state):
    return _idcol._toi_result(state)


def _restore_toi_batch_result(state, errors):
    return _idcol._toi_batch_result(state, errors)


def _polytope(A, b, beta, L):
    return _idcol.SmoothPolytope(A, b, beta, L)


def _polytope_from_vertices(V, beta, L):
    return _idcol.SmoothPolytope.from_vertices(V, beta, L)


def _shape_with_params(shape, theta):
    return shape.with_params(theta)
