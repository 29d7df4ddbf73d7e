"""Shapes, options and bad input: the C++ names, keyword arguments, messages
naming the field and the value, and reprs that show the parameters."""
import inspect
import itertools
import math
import os
import re

import numpy as np
import pytest

import idcol
from _helpers import OCTA, OCTA_B, superellipsoid_phi


def test_families_take_the_cpp_keyword_arguments_and_repr_shows_them():
    shapes = [
        (idcol.Sphere(R=0.8), "Sphere(R=0.8)"),
        (idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=8), "Superellipsoid(a=0.5, b=1.0, c=1.5, n=8.0)"),
        (idcol.SuperellipticCylinder(R=1.0, h=2.0, n=8), "SuperellipticCylinder(R=1.0, h=2.0, n=8.0)"),
        (idcol.SmoothTruncatedCone(Rb=1.0, Rt=1.5, a=1.5, b=1.5, beta=20),
         "SmoothTruncatedCone(Rb=1.0, Rt=1.5, a=1.5, b=1.5, beta=20.0)"),
    ]
    for s, want in shapes:
        assert repr(s) == want
        assert isinstance(s, idcol.Shape)
        # The repr is a constructor call that builds the same shape.
        assert repr(eval("idcol." + repr(s))) == want
    assert idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=8).n == 8.0
    assert idcol.SmoothTruncatedCone(Rb=1.0, Rt=1.5, a=1.5, b=1.5, beta=20).Rt == 1.5
    assert idcol.Sphere(R=0.8).family == "sphere"


def test_polytope_forms_agree_and_repr_round_trips():
    box = idcol.SmoothPolytope(np.array([[1, 0, 0], [-1, 0, 0], [0, 2, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]),
                               [0.5, 0.5, 1.4, 0.7, 0.3, 0.3], beta=20, L=2.0)
    # Rows are normalised, offsets scaled with them.
    assert np.allclose(np.linalg.norm(box.A, axis=1), 1.0)
    assert box.b[2] == pytest.approx(0.7)
    assert box.beta == 20 and box.L == 2.0 and box.A.shape == (6, 3)
    again = eval("idcol." + repr(box))
    assert np.array_equal(again.A, box.A) and np.array_equal(again.b, box.b)
    V = np.array(list(itertools.product([-0.5, 0.5], [-0.7, 0.7], [-0.3, 0.3])))
    hull = idcol.SmoothPolytope.from_vertices(V, beta=20, L=2.0)
    assert hull.A.shape == (6, 3) and hull.vertices.shape == (8, 3)
    # Same body: phi agrees at points inside, on and outside.
    rng = np.random.default_rng(0)
    for y in rng.normal(size=(50, 3)):
        assert hull.eval(y)[0] == pytest.approx(box.eval(y)[0], rel=1e-12, abs=1e-12)


def test_eval_against_the_closed_form():
    se = idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=3)
    rng = np.random.default_rng(1)
    checked = 0
    for y in rng.normal(size=(100, 3)):
        phi, grad, hess = se.eval(y)
        assert phi == pytest.approx(superellipsoid_phi([0.5, 1.0, 1.5], 3, y), rel=1e-12)
        assert grad.shape == (3,) and hess.shape == (3, 3)
        # Central differences of the closed form for the gradient.
        h = 1e-6
        fd = [(superellipsoid_phi([0.5, 1.0, 1.5], 3, y + h * e) - superellipsoid_phi([0.5, 1.0, 1.5], 3, y - h * e))
              / (2 * h) for e in np.eye(3)]
        assert np.allclose(grad, fd, rtol=1e-6, atol=1e-8)
        checked += 1
    assert checked == 100
    # Certified radii of a sphere are its radius.
    assert idcol.Sphere(R=0.8).radii == (0.8, 0.8)


TINY_BODIES = [idcol.Sphere(R=0.8), idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=8),
               idcol.Superellipsoid(a=1e-3, b=1.0, c=1.5, n=1), idcol.Superellipsoid(a=2.0, b=2.0, c=2.0, n=2.5),
               idcol.SuperellipticCylinder(R=1.0, h=2.0, n=8), idcol.SuperellipticCylinder(R=1e-3, h=2.0, n=1),
               idcol.SmoothTruncatedCone(Rb=1.0, Rt=1.5, a=1.5, b=1.5, beta=20.0),
               idcol.SmoothPolytope(OCTA, OCTA_B, beta=20.0)]


@pytest.mark.parametrize("shape", TINY_BODIES, ids=repr)
def test_eval_is_finite_within_the_underflow_of_the_origin(shape):
    """Points inside the body at 1e-320 (subnormal) and 1e-307 (normal, but
    1/|y| or the Hessian of order (2n - 1)/(|y| a^2) overflows): phi, grad,
    hess and the parameter derivatives are finite, phi = -1 for the
    homogeneous families (as at the origin); a little further out the
    answer is the exact one, not the origin's."""
    homogeneous = not isinstance(shape, (idcol.SmoothTruncatedCone, idcol.SmoothPolytope))
    for d in (5e-324, 1e-320, 1e-310, 1e-307, 1e-305, 1e-300):
        for u in ([1, 0, 0], [0, -1, 0], [1, 1, 1], [1, 1e-3, 0], [0, 0.6, -0.8]):
            y = d * np.asarray(u, float)
            out = shape.eval(y) + shape.eval_params(y)
            assert all(np.isfinite(v).all() for v in out), (d, u, out)
            if homogeneous:
                assert out[0] == -1.0
    if homogeneous:
        _, grad, hess = shape.eval([1e-200, 0.0, 0.0])
        assert grad[0] > 0 and np.isfinite(hess).all()


@pytest.mark.parametrize("make, field, value", [
    (lambda: idcol.Sphere(R=-1.0), "R", "-1"),
    (lambda: idcol.Sphere(R=float("nan")), "R", "nan"),
    (lambda: idcol.Superellipsoid(a=0.5, b=0.0, c=1.5, n=8), "b", "0"),
    (lambda: idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=0.5), "n", "0.5"),
    (lambda: idcol.SuperellipticCylinder(R=1.0, h=-2.0, n=8), "h", "-2"),
    (lambda: idcol.SmoothTruncatedCone(Rb=1.0, Rt=1.5, a=1.5, b=1.5, beta=1.0), "beta", "1"),
    (lambda: idcol.SmoothPolytope(OCTA, OCTA_B, beta=-3.0), "beta", "-3"),
    (lambda: idcol.SmoothPolytope(OCTA, OCTA_B, beta=20, L=0.0), "L", "0"),
])
def test_bad_parameters_raise_value_error_naming_field_and_value(make, field, value):
    with pytest.raises(ValueError) as e:
        make()
    msg = str(e.value)
    assert re.search(r"\b%s\b" % re.escape(field), msg), msg
    assert value in msg, msg


@pytest.mark.parametrize("make, pattern", [
    (lambda: idcol.SmoothPolytope(OCTA[:, :2], OCTA_B, beta=20), r"A must have shape \(m, 3\), got \(8, 2\)"),
    (lambda: idcol.SmoothPolytope(OCTA, OCTA_B[:5], beta=20), r"b must have shape \(8,\) to match A, got \(5,\)"),
    (lambda: idcol.SmoothPolytope.from_vertices(np.zeros((4, 2)), beta=20), r"V must have shape \(m, 3\)"),
    (lambda: idcol.Superellipsoid(0.5, 1.0, 1.5, 8).eval([1, 2]), r"y must have shape \(3,\), got \(2,\)"),
])
def test_bad_arrays_raise_value_error(make, pattern):
    with pytest.raises(ValueError, match=pattern):
        make()


def test_arrays_of_non_numbers_raise_type_error():
    with pytest.raises(TypeError, match=r"b must hold real numbers.*<U1"):
        idcol.SmoothPolytope(OCTA, ["a"] * 8, beta=20)
    with pytest.raises(TypeError, match=r"V must hold real numbers.*complex128"):
        idcol.SmoothPolytope.from_vertices(OCTA.astype(complex), beta=20)


def test_solver_options_fields_agree_everywhere():
    """The module's properties, repr, pickle state and the shipped stubs list
    the same fields in the same order: the C++ side expands the one list of
    idcol/options_fields.hpp (checked against SolverOptions at compile time),
    and the stubs are written by hand, so this is where one left behind shows."""
    import ast
    cls = idcol.SolverOptions
    props = [k for k, v in vars(cls).items() if isinstance(v, property)]
    in_repr = re.findall(r"(\w+)=", repr(cls()))
    in_state = list(cls().__getstate__().keys())
    stub = ast.parse(open(os.path.join(os.path.dirname(idcol.__file__), "__init__.pyi")).read())
    node = next(n for n in stub.body if isinstance(n, ast.ClassDef) and n.name == "SolverOptions")
    in_stub = [n.target.id for n in node.body if isinstance(n, ast.AnnAssign)]
    assert in_repr == in_state == props, (in_repr, in_state, props)
    assert in_stub == in_repr, "idcol/__init__.pyi's SolverOptions differs from the module: " + str(
        (sorted(set(in_repr) - set(in_stub)), sorted(set(in_stub) - set(in_repr))))
    # Each property's docstring says what validate() accepts.
    assert "finite and > 0" in cls.tolerance.__doc__ and "an integer in [1, 10000]" in cls.max_iterations.__doc__
    # Every field can be set on its own to a value other than its default.
    for f in props:
        d = getattr(cls(), f)
        v = (not d) if isinstance(d, bool) else (d + 1 if isinstance(d, int) and f != "warm_predictor_order"
                                                  else d - 1 if isinstance(d, int) else 1.5 if d == float("inf")
                                                  else d * (1.25 if d > 1 or f == "surrogate_factor" else 0.75))
        o = cls(**{f: v})
        assert getattr(o, f) == v and all(getattr(o, g) == getattr(cls(), g) for g in props if g != f), f


def test_solver_options_has_every_field_and_validates():
    o = idcol.SolverOptions()
    assert o.tolerance == 1e-10 and o.max_iterations == 25 and o.derivatives is False
    o = idcol.SolverOptions(tolerance=1e-12, max_iterations=40, derivatives=True, continuation=False)
    assert (o.tolerance, o.max_iterations, o.derivatives, o.continuation) == (1e-12, 40, True, False)
    fields = re.findall(r"(\w+)=", repr(idcol.SolverOptions()))
    for f in fields:   # every field in the repr is a property and a keyword
        v = getattr(o, f)
        idcol.SolverOptions(**{f: v})
    with pytest.raises(ValueError, match=r"'tolerance' must be finite and > 0, got -1"):
        idcol.SolverOptions(tolerance=-1.0)
    with pytest.raises(ValueError, match=r"'backtrack_factor'.*got 1\.5"):
        idcol.SolverOptions(backtrack_factor=1.5)
    with pytest.raises(TypeError, match=r"'max_iterations' must be an int, got 2\.5"):
        idcol.SolverOptions(max_iterations=2.5)
    with pytest.raises(TypeError, match=r"'derivatives' must be a bool, got 1"):
        idcol.SolverOptions(derivatives=1)
    with pytest.raises(TypeError, match=r"no field 'tolerence'"):
        idcol.SolverOptions(tolerence=1e-8)
    # Assignment is validated too, and a rejected value leaves the options unchanged.
    with pytest.raises(ValueError, match=r"'max_iterations'.*got 0"):
        o.max_iterations = 0
    assert o.max_iterations == 40
    assert idcol.SolverOptions().alpha_max == float("inf")
    assert idcol.SolverOptions(alpha_max=2.0).alpha_max == 2.0
    with pytest.raises(ValueError, match=r"'alpha_max' must be > 0.*got nan"):
        idcol.SolverOptions(alpha_max=float("nan"))
    with pytest.raises(ValueError, match=r"'alpha_max'.*got 0"):
        idcol.SolverOptions(alpha_max=0.0)


def test_hertz_model_validates():
    assert repr(idcol.HertzModel()) == "HertzModel(stiffness=1.0, exponent=1.5)"
    with pytest.raises(ValueError, match="stiffness"):
        idcol.HertzModel(stiffness=-1.0)
    with pytest.raises(ValueError, match="exponent"):
        idcol.HertzModel(exponent=0.5)


def test_status_enum_has_the_cpp_names():
    names = set(idcol.SolveStatus.__members__)
    assert {"Converged", "Concentric", "IterationLimit", "LineSearchFailed", "NumericalFailure",
            "SpuriousRoot", "InvalidInput", "Separated"} <= names
    assert idcol.SolveStatus(0) == idcol.SolveStatus.Converged
    codes = np.array([0, 1, 0], np.int32)
    assert list(codes == idcol.SolveStatus.Converged) == [True, False, True]


def test_help_documents_the_conventions():
    doc = idcol.__doc__
    for word in ["body-1", "(w, v)", "twist", "alpha*", "solve_batch"]:
        assert word in doc
    for f in [idcol.solve, idcol.solve_batch, idcol.alpha_gradient, idcol.contact_kinematics,
              idcol.contact_wrench, idcol.solution_sensitivity]:
        assert f.__doc__ and len(f.__doc__) > 80


def test_module_docstring_example_runs():
    import doctest
    failures, tried = doctest.testmod(idcol, verbose=False, report=True)[:2]
    assert tried >= 8 and failures == 0


def test_each_family_class_is_its_declaration_in_core():
    """Every family core declares (idcol/families.hpp, idcol.shape_families())
    is a class of the module whose keywords, defaults, properties, repr and
    pickling follow that declaration, and whose stub in idcol/__init__.pyi
    (written by hand) takes the same keywords with the same defaults."""
    import ast
    import pickle
    stub = ast.parse(open(os.path.join(os.path.dirname(idcol.__file__), "__init__.pyi")).read())
    stubs = {n.name: n for n in stub.body if isinstance(n, ast.ClassDef)}
    families = idcol.shape_families()
    assert [f["name"] for f in families] == ["sphere", "superellipsoid", "superelliptic_cylinder",
                                             "smooth_polytope", "smooth_truncated_cone"]
    for f in families:
        cls = getattr(idcol, f["type"])
        assert f["type"] in stubs, f["type"]
        if f["name"] == "smooth_polytope":
            continue  # its inputs are arrays (A, b, or vertices V), written out in its own class
        scalars = [p for p in f["params"] if not p["array"]]
        example = {p["key"]: p["example"] for p in scalars}
        s = cls(**example)
        assert s.family == f["name"] and s.param_names == list(example)
        assert list(s.params) == list(example.values())
        assert all(getattr(s, k) == v for k, v in example.items())
        assert repr(s) == f["type"] + "(" + ", ".join(f"{k}={float(v)!r}" for k, v in example.items()) + ")"
        assert repr(pickle.loads(pickle.dumps(s))) == repr(s)
        for p in scalars:
            if p["default"] is not None:
                without = {k: v for k, v in example.items() if k != p["key"]}
                assert getattr(cls(**without), p["key"]) == p["default"], p["key"]
            # Just past the edge of its range: refused, naming the field.
            edge = p["lower"] if p["lower_open"] else np.nextafter(p["lower"], -1.0)
            with pytest.raises(ValueError, match="'" + p["key"] + "'"):
                cls(**dict(example, **{p["key"]: edge}))
        init = next(n for n in stubs[f["type"]].body if isinstance(n, ast.FunctionDef) and n.name == "__init__")
        names = [a.arg for a in init.args.args[1:]]
        defaults = [ast.literal_eval(d) for d in init.args.defaults]
        assert names == list(example), (f["type"], names)
        declared = [p["default"] for p in scalars if p["default"] is not None]
        assert defaults == declared, (f["type"], defaults, declared)
