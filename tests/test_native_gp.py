"""The Rust GP core against the plain-NumPy reference, and by finite differences.

Random problems keep θ3/θ1 ≥ 1e-2, so K's condition number stays below ~N·100 and the dense
inverse of the reference is accurate to ~1e-12: the tolerances below (rtol 1e-9) are tight.
"""

import ast
import inspect
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import latentrl
from latentrl import _native, _reference
from latentrl._native import GpMap, InvalidInputError, LatentrlError, NumericalError, gplvm_nll_grad

RTOL = 1e-9


@st.composite
def gp_problems(draw):
    """Random inputs (N, q), outputs (N, p), θ and queries (M, q)."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n, q, p, m = (
        draw(st.integers(2, 30)),
        draw(st.integers(1, 3)),
        draw(st.integers(1, 4)),
        draw(st.integers(1, 8)),
    )
    theta1 = draw(st.floats(0.1, 10.0))
    theta = np.array([theta1, draw(st.floats(0.1, 5.0)), theta1 * draw(st.floats(1e-2, 1.0))])
    inputs = rng.normal(size=(n, q))
    outputs = rng.normal(size=(n, p)) * 3 + 1
    queries = np.vstack([inputs[: m // 2], rng.normal(size=(m - m // 2, q)) * 2])
    return inputs, outputs, theta, queries


@given(gp_problems())
def test_predict_matches_reference(problem):
    inputs, outputs, theta, queries = problem
    means, variances = GpMap(inputs, outputs, theta).predict(queries)
    ref_means, ref_variances = _reference.gp_predict(inputs, outputs, theta, queries)
    np.testing.assert_allclose(means, ref_means, rtol=RTOL, atol=RTOL * np.abs(outputs).max())
    np.testing.assert_allclose(variances, ref_variances, rtol=RTOL, atol=RTOL * theta[0])


@given(gp_problems())
def test_predict_one_equals_predict(problem):
    inputs, outputs, theta, queries = problem
    gp = GpMap(inputs, outputs, theta)
    means, variances = gp.predict(queries)
    for query, mean, variance in zip(queries, means, variances):
        one_mean, one_variance = gp.predict_one(query)
        np.testing.assert_allclose(one_mean, mean, rtol=1e-13, atol=1e-13)
        assert one_variance == pytest.approx(variance, rel=1e-13, abs=1e-15)


def test_gp_map_getters():
    gp = GpMap(np.zeros((3, 2)) + np.arange(3)[:, None], np.ones((3, 4)), np.array([1.0, 2.0, 0.5]))
    assert (gp.input_dim, gp.output_dim, gp.jitter) == (2, 4, 0.0)
    assert gp.theta == [1.0, 2.0, 0.5]


@given(gp_problems())
def test_nll_grad_matches_reference(problem):
    latent, outputs, theta, _ = problem
    centred = outputs - outputs.mean(axis=0)
    nll, grad_latent, grad_log_theta, jitter = gplvm_nll_grad(latent, centred, np.log(theta))
    ref_nll, ref_grad_latent, ref_grad_log_theta = _reference.gplvm_nll_grad(
        latent, centred, np.log(theta)
    )
    assert jitter == 0.0
    assert nll == pytest.approx(ref_nll, rel=RTOL, abs=RTOL * abs(ref_nll))
    scale = 1 + np.abs(ref_grad_latent).max()
    np.testing.assert_allclose(grad_latent, ref_grad_latent, rtol=RTOL, atol=RTOL * scale)
    np.testing.assert_allclose(grad_log_theta, ref_grad_log_theta, rtol=RTOL, atol=RTOL * scale)


@pytest.mark.parametrize("seed", range(3))
def test_nll_gradient_matches_finite_differences(seed):
    rng = np.random.default_rng(seed)
    latent = rng.normal(size=(12, 2))
    data = rng.normal(size=(12, 3))
    data -= data.mean(axis=0)
    log_theta = np.log([1.5, 0.8, 0.05])
    _, grad_latent, grad_log_theta, _ = gplvm_nll_grad(latent, data, log_theta)
    h = 1e-6

    def central(f, x):
        out = np.empty(x.size)
        for i in range(x.size):
            step = np.zeros(x.size)
            step[i] = h
            out[i] = (f(x + step.reshape(x.shape)) - f(x - step.reshape(x.shape))) / (2 * h)
        return out.reshape(x.shape)

    fd_latent = central(lambda z: gplvm_nll_grad(z, data, log_theta)[0], latent)
    fd_log_theta = central(lambda lt: gplvm_nll_grad(latent, data, lt)[0], log_theta)
    # Central differences are accurate to O(h²) plus rounding ~1e-16·|L|/h ≈ 1e-8 here.
    np.testing.assert_allclose(grad_latent, fd_latent, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(grad_log_theta, fd_log_theta, rtol=1e-6, atol=1e-6)


def test_duplicate_points_need_and_report_jitter():
    inputs = np.repeat(np.array([[0.0, 0.0], [1.0, 0.0]]), 3, axis=0)
    outputs = np.arange(6.0)[:, None]
    tiny_noise = np.array([1.0, 1.0, 1e-300])
    gp = GpMap(inputs, outputs, tiny_noise)
    assert gp.jitter > 0
    assert gplvm_nll_grad(inputs, outputs - outputs.mean(), np.log(tiny_noise))[3] == gp.jitter
    assert GpMap(inputs, outputs, np.array([1.0, 1.0, 1e-6])).jitter == 0.0


def test_bad_inputs_raise_named_errors():
    ok_in, ok_out, theta = np.zeros((3, 2)), np.zeros((3, 1)), np.array([1.0, 1.0, 0.1])
    with pytest.raises(InvalidInputError, match="outputs"):
        GpMap(ok_in, np.zeros((4, 1)), theta)
    with pytest.raises(InvalidInputError, match="theta"):
        GpMap(ok_in, ok_out, np.array([1.0, 1.0]))
    with pytest.raises(InvalidInputError, match="theta2"):
        GpMap(ok_in, ok_out, np.array([1.0, -1.0, 0.1]))
    with pytest.raises(InvalidInputError, match=r"inputs.*non-finite"):
        GpMap(np.array([[0.0, np.nan], [1.0, 1.0], [2.0, 2.0]]), ok_out, theta)
    gp = GpMap(ok_in + np.arange(3)[:, None], ok_out, theta)
    with pytest.raises(InvalidInputError, match="query"):
        gp.predict(np.zeros((2, 3)))
    with pytest.raises(InvalidInputError, match="x: expected shape"):
        gp.predict_one(np.zeros(3))
    with pytest.raises(InvalidInputError, match="log_theta"):
        gplvm_nll_grad(ok_in, ok_out, np.zeros(4))
    assert issubclass(InvalidInputError, LatentrlError) and issubclass(NumericalError, ValueError)


def test_stub_declares_the_native_module():
    """A cheap stand-in for mypy.stubtest: the same public names, the same parameter names."""
    stub = ast.parse((Path(latentrl.__file__).parent / "_native.pyi").read_text())
    declared = {
        node.name: node for node in stub.body if isinstance(node, (ast.ClassDef, ast.FunctionDef))
    }
    constants = {node.target.id for node in stub.body if isinstance(node, ast.AnnAssign)}
    assert constants == {"__version__", "MAX_EPISODES", "MAX_GP_POINTS"}
    assert all(isinstance(getattr(_native, name), int) for name in constants - {"__version__"})
    assert set(declared) | constants == set(_native.__all__)
    assert isinstance(_native.__version__, str) and latentrl.__version__ == _native.__version__

    def stub_params(node):
        args = node.args
        positional = [a.arg for a in args.posonlyargs + args.args if a.arg not in ("self", "cls")]
        return positional + ["*" + a.arg for a in args.kwonlyargs]

    def runtime_params(obj):
        kw_only = inspect.Parameter.KEYWORD_ONLY
        return [
            ("*" if p.kind is kw_only else "") + p.name
            for p in inspect.signature(obj).parameters.values()
            if p.name not in ("self", "cls")
        ]

    for name, node in declared.items():
        obj = getattr(_native, name)
        if isinstance(node, ast.FunctionDef):
            assert stub_params(node) == runtime_params(obj), name
        elif not issubclass(obj, BaseException):
            methods = {n.name: n for n in node.body if isinstance(n, ast.FunctionDef)}
            assert {m for m in methods if not m.startswith("_")} == {
                m for m in dir(obj) if not m.startswith("_")
            }
            if "__new__" in methods:
                assert stub_params(methods["__new__"]) == runtime_params(obj), name
            else:  # built by its static methods only (Task.load, Task.from_dict)
                with pytest.raises(TypeError):
                    obj()
            for method, mnode in methods.items():
                if not method.startswith("_") and not mnode.decorator_list:
                    assert stub_params(mnode) == runtime_params(getattr(obj, method)), method


def test_fortran_ordered_arrays_are_read_by_rows():
    """A Fortran-ordered (N, q) array is N points, as a C-ordered one: numpy would hand out its
    buffer in column order, which read as rows is the transpose (a silent bug until issue #15)."""
    rng = np.random.default_rng(4)
    z, x = rng.normal(size=(12, 2)), rng.normal(size=(12, 3))
    theta = np.array([1.0, 0.5, 1e-3])
    c_order = GpMap(z, x, theta).predict(z[:5])
    f_order = GpMap(np.asfortranarray(z), np.asfortranarray(x), theta).predict(np.asfortranarray(z[:5]))
    for a, b in zip(c_order, f_order):
        np.testing.assert_array_equal(a, b)
