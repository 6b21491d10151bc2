"""Property-based fuzzing of the public API and the native boundary (issue "Reliability").

Every case ends in one of two ways: a valid result (finite for finite input) or a
ValueError / TypeError / OSError (a LatentrlError is a ValueError). Anything else fails the
test, in particular pyo3's PanicException, which is a BaseException and so is never caught
as one of the allowed errors. The number of cases comes from the Hypothesis profile
(HYPOTHESIS_PROFILE=fast|thorough, tests/conftest.py).
"""

from __future__ import annotations

import io
import json
import math
import tempfile
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from run_folder_readers import FILES, json_mutations, make_folder, npz_mutations, read_file, read_mutated

import latentrl
from latentrl import GPLVM, PCA, Task, _native, load_demos
from latentrl._native import (
    GpMap,
    InternalError,
    InvalidInputError,
    LatentrlError,
    arms_elbows,
    arms_fk,
    arms_ik,
    gplvm_nll_grad,
    run_task_trials,
)

ALLOWED = (ValueError, TypeError, OSError)
FUZZ = settings(suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

# ---------------------------------------------------------------------------------------------
# Arrays of any dtype, shape and value


FLOATS = st.one_of(
    st.floats(-1e3, 1e3),
    st.sampled_from([0.0, -0.0, np.nan, np.inf, -np.inf, 1e300, -1e300, 1e150, 1e-150, 1e-300, 5e-324]),
)
# float64 (what the native functions take) half the time, any other dtype otherwise.
DTYPES = st.one_of(st.just("f8"), st.sampled_from(["f4", "i8", "u1", "?", "c16", "O", "<U3"]))


@st.composite
def arrays(draw: st.DrawFn, max_dims: int = 3, max_side: int = 6) -> Any:
    """An array of a random dtype and shape (0 to `max_dims` axes, each 0 to `max_side`),
    with NaN, inf and extreme magnitudes among the floats; sometimes a nested list instead."""
    shape = draw(
        st.one_of(
            hnp.array_shapes(min_dims=min(2, max_dims), max_dims=min(2, max_dims), max_side=max_side),
            hnp.array_shapes(min_dims=0, max_dims=max_dims, min_side=0, max_side=max_side),
        )
    )
    dtype = draw(DTYPES)
    if dtype == "O":
        elements: st.SearchStrategy[Any] = st.one_of(FLOATS, st.none(), st.text(max_size=2))
    elif dtype == "<U3":
        elements = st.text(alphabet="0123456789.-ex", max_size=3)
    elif dtype in ("f8", "f4"):
        elements = FLOATS if dtype == "f8" else st.floats(-1e3, 1e3, width=32)
    else:
        elements = hnp.from_dtype(np.dtype(dtype), allow_nan=False, allow_infinity=False)
        if dtype == "c16":
            elements = st.complex_numbers(max_magnitude=1e3)
    array = draw(hnp.arrays(dtype=np.dtype(dtype), shape=shape, elements=elements))
    if draw(st.booleans()) and array.ndim == 2 and array.shape[1] > 1:
        array = array[:, ::2]  # not C-contiguous
    return array.tolist() if draw(st.integers(0, 9)) == 0 else array


@st.composite
def finite_matrices(draw: st.DrawFn, cols: int | None = None, max_rows: int = 8) -> Any:
    """A float64 (N, cols) array of finite values, magnitudes up to 1e3."""
    rows = draw(st.integers(1, max_rows))
    cols = draw(st.integers(1, 4)) if cols is None else cols
    return draw(hnp.arrays(np.float64, (rows, cols), elements=st.floats(-1e3, 1e3)))


def attempt(fn: Any, *args: Any, **kwargs: Any) -> Any:
    """`fn(*args, **kwargs)`, or None if it raised an allowed error; anything else propagates.
    The outcome is a Hypothesis event (see `--hypothesis-show-statistics`)."""
    try:
        result = fn(*args, **kwargs)
    except ALLOWED as err:
        event(f"{getattr(fn, '__name__', '?')}: {type(err).__name__}")
        return None
    event(f"{getattr(fn, '__name__', '?')}: result")
    return result


def all_finite(*values: Any) -> bool:
    return all(np.all(np.isfinite(np.asarray(v, dtype=np.float64))) for v in values)


def is_finite_float(value: Any) -> bool:
    try:
        return bool(np.all(np.isfinite(np.asarray(value, dtype=np.float64))))
    except (TypeError, ValueError):
        return False


# ---------------------------------------------------------------------------------------------
# The exception hierarchy and the panic guard


def test_exception_hierarchy() -> None:
    assert issubclass(InternalError, LatentrlError)
    assert issubclass(LatentrlError, ValueError)
    assert latentrl.InternalError is InternalError
    assert "please report" in (InternalError.__doc__ or "")
    assert _native.InternalError is InternalError


@pytest.mark.parametrize(
    ("call", "says"),
    [
        (lambda: GpMap(np.zeros((0, 2)), np.zeros((0, 1)), np.ones(3)), "inputs is empty"),
        (lambda: GpMap(np.zeros((3, 2)), np.zeros((2, 1)), np.ones(3)), "outputs: expected shape"),
        (lambda: GpMap(np.zeros((3, 2)), np.zeros((3, 1)), np.array([1.0, -1.0, 0.0])), "theta2"),
        (lambda: GpMap(np.ones((3, 1)), np.ones((3, 1)), np.array([1.0, 1.0, 0.0])), "theta3"),
        (lambda: gplvm_nll_grad(np.zeros((3, 2)), np.zeros((3, 4)), np.array([800.0, -800.0, 800.0])), "theta1"),
        (lambda: arms_ik(np.full((2, 4), 5.0)), "unreachable"),
        (lambda: arms_fk(np.full((1, 4), np.nan)), "non-finite"),
        (lambda: arms_elbows(np.zeros((3, 3))), "expected shape"),
    ],
)
def test_known_bad_inputs_raise_value_errors_not_panics(call: Any, says: str) -> None:
    with pytest.raises(InvalidInputError, match=says):
        call()


def test_one_point_in_one_dimension_is_a_valid_gplvm_objective() -> None:
    """N = D = q = 1 with log θ = 0 is a GP of one point (issue #22 asked for a decision): valid,
    K = θ₁ + θ₃ = 2, so NLL = ½ log(2π · 2) + ½ · 0² / 2, against the closed form."""
    nll, grad_z, grad_log_theta, _ = gplvm_nll_grad(np.zeros((1, 1)), np.zeros((1, 1)), np.zeros(3))
    assert nll == pytest.approx(0.5 * math.log(4 * math.pi), rel=1e-12)
    assert grad_z.shape == (1, 1) and grad_z[0, 0] == 0.0
    # d NLL / d log θ₁ = d NLL / d log θ₃ = ½ θ / K = ¼ (no data term at y = 0); θ₂ has no effect.
    np.testing.assert_allclose(grad_log_theta, [0.25, 0.0, 0.25], rtol=1e-12)


# ---------------------------------------------------------------------------------------------
# GpMap and the GPLVM objective


@FUZZ
@given(inputs=arrays(), outputs=arrays(), theta=arrays(max_dims=1, max_side=4), queries=arrays())
def test_gp_map_any_arrays(inputs: Any, outputs: Any, theta: Any, queries: Any) -> None:
    gp = attempt(GpMap, inputs, outputs, theta)
    if gp is None:
        return
    for predict in (gp.predict, gp.predict_mean, gp.predict_one):
        result = attempt(predict, queries)
        if result is not None and is_finite_float(queries):
            assert all_finite(*result) if isinstance(result, tuple) else all_finite(result)


@FUZZ
@given(
    data=st.data(),
    theta=hnp.arrays(np.float64, 3, elements=st.floats(1e-8, 1e8)),
)
def test_gp_map_finite_inputs_give_finite_predictions(data: st.DataObject, theta: Any) -> None:
    inputs = data.draw(finite_matrices())
    outputs = np.resize(data.draw(finite_matrices()), (inputs.shape[0], data.draw(st.integers(1, 4))))
    gp = attempt(GpMap, inputs, outputs, theta)
    if gp is None:
        return
    queries = data.draw(finite_matrices(cols=inputs.shape[1]))
    means, variances = gp.predict(queries)
    assert all_finite(means, variances, gp.predict_mean(queries))
    assert np.all(variances >= 0)
    mean, variance = gp.predict_one(queries[0])
    assert all_finite(mean, variance)


@FUZZ
@given(latent=arrays(), data=arrays(), log_theta=arrays(max_dims=1, max_side=4))
def test_gplvm_nll_grad_any_arrays(latent: Any, data: Any, log_theta: Any) -> None:
    result = attempt(gplvm_nll_grad, latent, data, log_theta)
    if result is not None and is_finite_float(latent) and is_finite_float(data):
        assert is_finite_float(log_theta)
        nll, grad_latent, grad_log_theta, jitter = result
        assert all_finite(nll, grad_latent, grad_log_theta, jitter)


@FUZZ
@given(
    data=st.data(),
    log_theta=hnp.arrays(np.float64, 3, elements=st.floats(-30, 30)),
)
def test_gplvm_nll_grad_finite_inputs(data: st.DataObject, log_theta: Any) -> None:
    latent = data.draw(finite_matrices(max_rows=10))
    centred = data.draw(finite_matrices(max_rows=latent.shape[0]))
    centred = np.resize(centred, (latent.shape[0], centred.shape[1]))
    result = attempt(gplvm_nll_grad, latent, centred, log_theta)
    if result is not None:
        assert all_finite(*result)


# ---------------------------------------------------------------------------------------------
# PCA and GPLVM


@FUZZ
@given(X=arrays(), Z=arrays(), n_components=st.sampled_from([1, 2, 3, 0, -1, 2.5, "2", None, True]))
def test_pca_any_arrays(X: Any, Z: Any, n_components: Any) -> None:
    pca = attempt(PCA(n_components).fit, X)
    if pca is None:
        return
    for method, arg in ((pca.transform, X), (pca.transform, Z), (pca.inverse_transform, Z)):
        result = attempt(method, arg)
        if result is not None:
            assert all_finite(result)


@FUZZ
@given(X=arrays(max_side=5), Z=arrays(max_side=5), n_components=st.sampled_from([1, 2, 0, 2.0]))
def test_gplvm_any_arrays(X: Any, Z: Any, n_components: Any) -> None:
    model = attempt(GPLVM(n_components, max_iter=5).fit, X)
    if model is None:
        return
    assert all_finite(model.Z_, model.theta_, model.nll_)
    for method in ("gp", "projection"):
        result = attempt(model.transform, X, method=method)
        if result is not None:
            assert all_finite(result)
    for method_fn in (model.inverse_transform, model.predict_variance):
        result = attempt(method_fn, Z)
        if result is not None:
            assert all_finite(result)


# ---------------------------------------------------------------------------------------------
# Demonstration files

NAMES = ["a", "b", "c"]


def csv_text(rows: list[list[Any]], header: list[str]) -> str:
    return "\n".join(",".join(str(c) for c in row) for row in [header, *rows]) + "\n"


@st.composite
def demo_files(draw: st.DrawFn) -> tuple[str, bytes]:
    """(suffix, bytes) of a CSV/JSON/NPZ file: valid, then perhaps mangled."""
    suffix = draw(st.sampled_from([".csv", ".json", ".npz"]))
    cell = st.one_of(FLOATS, st.text(max_size=3), st.none(), st.booleans(), st.just([1.0]))
    n = draw(st.integers(0, 4))
    rows = [[draw(st.floats(-10, 10)) for _ in NAMES] for _ in range(n)]
    header = list(NAMES)
    mangle = draw(st.sampled_from(["none", "ragged", "cell", "header", "dup", "truncate", "bytes"]))
    if mangle == "ragged" and rows:
        rows[draw(st.integers(0, n - 1))].append(1.0)
    elif mangle == "cell" and rows:
        rows[draw(st.integers(0, n - 1))][draw(st.integers(0, 2))] = draw(cell)
    elif mangle == "header":
        header = draw(st.lists(st.text(max_size=3), max_size=4))
    elif mangle == "dup":
        header = ["a", "a", "b"]
    if suffix == ".csv":
        blob = csv_text(rows, header).encode()
    elif suffix == ".json":
        doc: Any = {"joint_names": header, "postures": rows}
        if draw(st.booleans()):
            doc = draw(st.sampled_from([[], None, 3, {"postures": rows}, {"joint_names": 1, "postures": 2}]))
        blob = json.dumps(doc).encode()
    else:
        buffer = io.BytesIO()
        try:
            postures = np.array(rows)
        except ValueError:  # ragged rows, or a list in a cell
            postures = np.array(rows, dtype=object)
        kind = draw(st.sampled_from(["f8", "i4", "?", "c16", "U2", "keep"]))
        if kind != "keep" and postures.dtype != object:
            try:
                postures = postures.astype(kind)
            except (TypeError, ValueError):  # a string cell
                pass
        names = draw(st.sampled_from([np.array(header, dtype=str), np.array([1, 2, 3]), np.array("a")]))
        arrays_: dict[str, Any] = {"postures": postures, "joint_names": names}
        if draw(st.booleans()):
            arrays_.pop(draw(st.sampled_from(["postures", "joint_names"])))
        np.savez(buffer, **arrays_)
        blob = buffer.getvalue()
    if mangle == "truncate":
        blob = blob[: draw(st.integers(0, len(blob)))]
    elif mangle == "bytes":
        blob = draw(st.binary(max_size=64))
    return suffix, blob


@FUZZ
@given(file=demo_files(), expected=st.sampled_from([None, NAMES, ["c", "a", "b"], ["x"]]))
def test_load_demos_malformed_files(file: tuple[str, bytes], expected: Any) -> None:
    suffix, blob = file
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"demos{suffix}"
        path.write_bytes(blob)
        demos = attempt(load_demos, path, expected_joints=expected)
    if demos is not None:
        assert demos.postures.ndim == 2 and demos.postures.shape[1] == len(demos.joint_names)
        assert all_finite(demos.postures)


# ---------------------------------------------------------------------------------------------
# Kinematics of the planar arms


@FUZZ
@given(values=arrays(max_dims=2, max_side=5))
def test_arms_kinematics_any_arrays(values: Any) -> None:
    for fn in (arms_fk, arms_elbows, arms_ik):
        result = attempt(fn, values)
        if result is not None:
            assert is_finite_float(values) and all_finite(result)


@FUZZ
@given(postures=hnp.arrays(np.float64, st.tuples(st.integers(1, 20), st.just(4)), elements=st.floats(-1e6, 1e6)))
def test_arms_fk_ik_round_trip_is_finite(postures: Any) -> None:
    hands = arms_fk(postures)
    assert all_finite(hands, arms_elbows(postures))
    back = attempt(arms_ik, hands)  # a hand at the reach limit may round to unreachable
    if back is not None:
        assert all_finite(back)
        np.testing.assert_allclose(arms_fk(back), hands, atol=1e-6)


# ---------------------------------------------------------------------------------------------
# Malformed URDF robots for the task runner (the two-arm task of Experiment 2)

ARMS = Task.shipped("two_arms")
URDF = ARMS.urdf_path.read_text()

MUTATIONS = {
    "truncate": None,
    "wrong robot tag": ("<robot ", "<robto "),
    "wrong link tag": ("<link name=\"left_forearm\">", "<lnk name=\"left_forearm\">"),
    "wrong joint tag": ("<joint name=\"left_elbow\"", "<jiont name=\"left_elbow\""),
    "missing parent": ("<parent link=\"left_upper_arm\"/>", "<parent link=\"nowhere\"/>"),
    "cycle": ("</robot>", "<joint name=\"loop\" type=\"fixed\"><parent link=\"left_forearm\"/>"
              "<child link=\"base\"/></joint></robot>"),
    "zero mass": ("<mass value=\"0.5\"/>", "<mass value=\"0\"/>"),
    "negative mass": ("<mass value=\"0.5\"/>", "<mass value=\"-1\"/>"),
    "nan mass": ("<mass value=\"0.5\"/>", "<mass value=\"nan\"/>"),
    "huge mass": ("<mass value=\"0.5\"/>", "<mass value=\"1e308\"/>"),
    "zero inertia": ("ixx=\"1.0e-4\"", "ixx=\"0\""),
    "nan limit": ("lower=\"-3.3\"", "lower=\"nan\""),
    "inf limit": ("upper=\"6.6\"", "upper=\"inf\""),
    "empty limit": ("lower=\"-3.3\" upper=\"0.3\"", "lower=\"0.3\" upper=\"-3.3\""),
    "nan origin": ("<origin xyz=\"0.3 0 0\" rpy=\"0 0 0\"/>", "<origin xyz=\"nan 0 0\" rpy=\"0 0 0\"/>"),
    "zero axis": ("<axis xyz=\"0 0 1\"/>", "<axis xyz=\"0 0 0\"/>"),
    "spherical joint": ("type=\"revolute\"", "type=\"spherical\""),
    "floating joint": ("type=\"revolute\"", "type=\"floating\""),
    "unknown joint": ("type=\"revolute\"", "type=\"hinge\""),
    "prismatic joint": ("type=\"revolute\"", "type=\"prismatic\""),
    "mesh": ("<capsule radius=\"0.02\" length=\"0.26\"/>", "<mesh filename=\"arm.stl\"/>"),
    "duplicate link": ("<link name=\"left_forearm\">", "<link name=\"left_upper_arm\">"),
    "no hands": ("name=\"left_hand\"", "name=\"left_paw\""),
    "not xml": ("<?xml", "<<?xml"),
    "nan inertia": ("iyy=\"3.8e-3\"", "iyy=\"nan\""),
    "negative effort": ("effort=\"1000\"", "effort=\"-1\""),
    "nan velocity": ("velocity=\"20\"", "velocity=\"nan\""),
    "no limit": ("<limit lower=\"-3.5\" upper=\"6.6\" effort=\"1000\" velocity=\"20\"/>", ""),
    "continuous joint": ("type=\"revolute\"", "type=\"continuous\""),
    "intact": ("", ""),
}


def test_mutations_apply_to_the_shipped_urdf() -> None:
    """Each mutation changes the URDF: a pattern the file no longer holds would fuzz nothing."""
    for name, mutation in MUTATIONS.items():
        if mutation is not None and name != "intact":
            assert mutation[0] in URDF, name


@pytest.fixture(scope="module")
def arms_maps() -> dict[str, Any]:
    """A decoder latent (2) → posture (4) and an encoder back, through postures that hold the
    grip (hands 0.1 m apart) below the walls, so that the intact URDF runs its episode."""
    grid = np.linspace(-1, 1, 6)
    latent = np.array([(a, b) for a in grid for b in grid])
    left = np.column_stack([-0.05 + 0.1 * latent[:, 0], 0.15 + 0.08 * latent[:, 1]])
    postures = arms_ik(np.column_stack([left, left + [0.1, 0.0]]))
    theta = np.array([1.0, 1.0, 1e-6])
    return {
        "decoder": GpMap(latent, postures, theta),
        "encoder": GpMap(postures, latent, theta),
        "latent_low": np.full(2, -1.0),
        "latent_high": np.full(2, 1.0),
    }


def run_arms(urdf_text: str, maps: dict[str, Any], overrides: dict[str, Any] | None = None) -> dict[str, Any]:
    """One 3-step episode of the two-arm task with its URDF replaced by `urdf_text` and its
    keys by `overrides` (a Task error is raised before the run)."""
    with tempfile.TemporaryDirectory() as tmp:
        Path(tmp, "robot.urdf").write_text(urdf_text)
        config = {**ARMS.to_dict(), "urdf": "robot.urdf"}
        task = Task.from_dict(config, tmp).replace({"episode.max_steps": 3, **(overrides or {})})
        return run_task_trials(task._native, **maps, n_trials=1, episodes=1, base_seed=0)


def test_intact_urdf_runs(arms_maps: dict[str, Any]) -> None:
    out = run_arms(URDF, arms_maps)
    assert all_finite(out["returns"]) and out["steps"][0, 0] >= 1


@FUZZ
@given(
    names=st.lists(st.sampled_from(sorted(MUTATIONS)), min_size=1, max_size=3),
    cut=st.floats(0, 1),
)
def test_task_runner_malformed_urdf(arms_maps: dict[str, Any], names: list[str], cut: float) -> None:
    text = URDF
    for name in names:
        mutation = MUTATIONS[name]
        if mutation is None:
            text = text[: int(cut * len(text))]
        else:
            text = text.replace(*mutation, 1)
    out = attempt(run_arms, text, arms_maps)
    if out is not None:
        assert all_finite(out["returns"], out["steps"])


# ---------------------------------------------------------------------------------------------
# Extreme values of every task key and of every key of Experiment 1's toy

NUMBERS = st.one_of(
    st.floats(-10, 10),
    st.sampled_from([0.0, -1.0, 1.0, 1e-300, 1e300, -1e300, np.nan, np.inf]),
    st.integers(-3, 50),
)
VALUES = st.one_of(
    NUMBERS, st.lists(NUMBERS, max_size=4), st.lists(st.lists(NUMBERS, max_size=3), max_size=3),
    st.text(max_size=8), st.none(), st.booleans(), st.dictionaries(st.text(max_size=3), NUMBERS, max_size=2),
)
TASK_KEYS = sorted(row["key"] for row in _native.task_schema() if "[]" not in row["key"] and "NAME" not in row["key"])
BIMANUAL_KEYS = sorted(row["key"] for row in _native.bimanual_schema())


@FUZZ
@given(overrides=st.dictionaries(st.sampled_from(TASK_KEYS), VALUES, min_size=1, max_size=3))
def test_task_runner_extreme_task_keys(arms_maps: dict[str, Any], overrides: dict[str, Any]) -> None:
    out = attempt(run_arms, URDF, arms_maps, overrides)
    if out is not None:
        assert all_finite(out["returns"], out["steps"])


@FUZZ
@given(
    config=st.dictionaries(st.sampled_from(BIMANUAL_KEYS), VALUES, max_size=3),
    latent=st.booleans(),
)
def test_run_bimanual_trials_extreme_config(arms_maps: dict[str, Any], config: dict[str, Any], latent: bool) -> None:
    tables: dict[str, dict[str, Any]] = {"plant": {"max_steps": 20}, "learner": {}}
    for key, value in config.items():
        table, name = key.split(".")
        tables[table][name] = value if name != "max_steps" else min(value, 20) if isinstance(value, int) else value
    maps = arms_maps if latent else {}
    out = attempt(_native.run_bimanual_trials, n_trials=1, episodes=2, base_seed=0, **tables, **maps)
    if out is not None:
        assert all_finite(out["returns"], out["learner_low"], out["learner_high"])


# ---------------------------------------------------------------------------------------------
# Finite inputs of extreme scale: a finite result or an error, never NaN/inf


@FUZZ
@given(
    seed=st.integers(0, 2**32 - 1),
    data_exp=st.integers(-300, 300),
    latent_exp=st.integers(-300, 300),
    log_theta=hnp.arrays(np.float64, 3, elements=st.floats(-700, 700)),
)
def test_extreme_scales_give_finite_results_or_errors(
    seed: int, data_exp: int, latent_exp: int, log_theta: Any
) -> None:
    rng = np.random.default_rng(seed)
    latent = rng.normal(size=(6, 2)) * 10.0**latent_exp
    data = rng.normal(size=(6, 3)) * 10.0**data_exp
    result = attempt(gplvm_nll_grad, latent, data - data.mean(axis=0), log_theta)
    if result is not None:
        assert all_finite(*result)
    gp = attempt(GpMap, latent, data, np.exp(np.clip(log_theta, -700, 700)))
    if gp is not None:
        result = attempt(gp.predict, latent)
        if result is not None:
            assert all_finite(*result)
    model = attempt(GPLVM(2, max_iter=3).fit, data)
    if model is not None:
        assert all_finite(model.Z_, model.theta_, model.inverse_transform(model.Z_), model.transform(data))


# ---------------------------------------------------------------------------------------------
# The run-folder readers (issue #38): results.json, returns.npz, gplvm.npz, policy.npz,
# rollout.json and rollout.npz of a tiny `latentrl train` run, each mutated and read back by every
# reader of it (tests/run_folder_readers.py); fuzz/fuzz_run_folder.py is the atheris target.

@pytest.fixture(scope="module")
def run_folder(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, bytes]]:
    """A tiny train run and rollout (`run_folder_readers.make_folder`, ~4 s) and its files' bytes."""
    root = make_folder(tmp_path_factory.mktemp("run_folder"))
    return root, {name: (root / name).read_bytes() for name in FILES}


def test_the_intact_run_folder_reads(run_folder: tuple[Path, dict[str, bytes]]) -> None:
    root, _ = run_folder
    for name in FILES:
        read_file(root, name)


@settings(FUZZ, max_examples=6 * settings().max_examples)
@given(data=st.data(), name=st.sampled_from(FILES))
def test_run_folder_readers_mutated_files(run_folder: tuple[Path, dict[str, bytes]], data: st.DataObject,
                                          name: str) -> None:
    """Each file of a run folder mutated (JSON: a value deleted, retyped, nested, odd; NPZ: an
    array dropped, renamed, retyped, reshaped, odd values; either: cut or flipped bytes) is read
    by every reader of it, or refused with a ValueError or OSError naming the file (or the
    folder); never another exception or NaN where the run stored numbers (issue #38)."""
    root, original = run_folder
    blob = original[name]
    mutated = data.draw(json_mutations(blob.decode()) if name.endswith(".json") else npz_mutations(blob))
    event(f"{name}: {read_mutated(root, name, mutated, blob)}")


def edited_npz(path: Path, **changes: Any) -> None:
    """Rewrites the NPZ at `path` with arrays replaced (a value), added, or dropped (None)."""
    with np.load(path) as npz:
        arrays = {k: npz[k] for k in npz.files}
    for key, value in changes.items():
        if value is None:
            del arrays[key]
        else:
            arrays[key] = value
    np.savez(path, **arrays)


def corrupt_header(path: Path) -> None:
    """`path` an NPZ whose one array's header has an unclosed parenthesis (its CRC right)."""
    buffer = io.BytesIO()
    np.save(buffer, np.zeros((2, 3)))
    npy = buffer.getvalue().replace(b"(2, 3)", b"(2, 3 ")
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("latent.npy", npy)


def unknown_compression(path: Path) -> None:
    """`path`'s first zip member marked with compression method 99 (no such method)."""
    blob = bytearray(path.read_bytes())
    blob[blob.index(b"PK\x03\x04") + 8] = 99
    blob[blob.index(b"PK\x01\x02") + 10] = 99
    path.write_bytes(bytes(blob))


def edited_json(path: Path, **changes: Any) -> None:
    path.write_text(json.dumps({**json.loads(path.read_text()), **changes}))


# Issue #38: what the run-folder fuzzers found, each once another exception (or NaN drawn silently).
FOUND = {
    "preset_json not JSON (JSONDecodeError naming no file)": (
        "out/returns.npz", lambda p: edited_npz(p, preset_json=np.array("{")), r"returns\.npz: preset_json is not"),
    "preset_json a number (TypeError)": (
        "out/returns.npz", lambda p: edited_npz(p, preset_json=np.array("1")), r"returns\.npz: preset_json is not"),
    "an array of another number of trials (IndexError)": (
        "out/returns.npz", lambda p: edited_npz(p, latent_mean_state=np.zeros((2, 3, 2))),
        r"returns\.npz: latent_mean_state: expected one row per trial"),
    "NaN weights (V drawn from NaN)": (
        "out/returns.npz", lambda p: edited_npz(p, latent_weights=np.full((1, 4), np.nan)),
        r"returns\.npz: latent_weights of trial 0 holds NaN"),
    "no recorded paths (a message naming no file)": (
        "out/returns.npz", lambda p: edited_npz(p, latent_paths=np.zeros((1, 0, 2, 2))),
        r"returns\.npz: --episode 2: the run recorded training episodes \[\]"),
    "an array header with an unclosed parenthesis (TokenError)": (
        "out/returns.npz", corrupt_header, r"returns\.npz: not a readable NPZ file"),
    "an unknown compression method (NotImplementedError)": (
        "out/gplvm.npz", unknown_compression, r"gplvm\.npz: not a readable NPZ file"),
    "n_features_in_ infinite (OverflowError)": (
        "out/gplvm.npz", lambda p: edited_npz(p, n_features_in_=np.array(np.inf)), r"gplvm\.npz: inconsistent"),
    "Z_ one-dimensional (IndexError)": (
        "out/gplvm.npz", lambda p: edited_npz(p, Z_=np.zeros(5)), r"gplvm\.npz: inconsistent .*Z_"),
    "Z_ complex (ComplexWarning, an error under pytest)": (
        "out/gplvm.npz", lambda p: edited_npz(p, Z_=np.zeros((5, 2), dtype=complex)), r"gplvm\.npz: inconsistent .*Z_"),
    "a preset's task true (TypeError)": (
        "out/results.json", lambda p: edited_json(p, preset={**json.loads(p.read_text())["preset"], "task": True}),
        r"results\.json: preset\.task must be a JSON object"),
    "a policy's latent box complex (ComplexWarning, an error under pytest)": (
        "out/policy.npz", lambda p: edited_npz(p, latent_high=np.zeros(2, dtype=complex)),
        r"policy\.npz: latent_high: expected real numbers"),
    "a policy's task a JSON list (TypeError)": (
        "out/policy.npz", lambda p: edited_npz(p, task=np.array("[]")), r"policy\.npz: its task is not a table"),
    "a policy's record without its ends (KeyError in report)": (
        "out/policy.npz", lambda p: edited_npz(p, **{"record.ends": None}), r"policy\.npz: .*record\.ends"),
    "a rollout's policy_from_out a list (TypeError)": (
        "rollout/rollout.json", lambda p: edited_json(p, policy_from_out=[]), r"rollout\.json: policy_from_out must"),
    "a rollout's trials a number (TypeError)": (
        "rollout/rollout.json", lambda p: edited_json(p, trials=3), r"rollout\.json: trials must be a list"),
    "a rollout's trials without the one asked for (a message naming no file)": (
        "rollout/rollout.json", lambda p: edited_json(p, trials=[]), r"--trial 0: the rollout in .*rollout ran trials"),
}


@pytest.mark.parametrize("found", sorted(FOUND))
def test_what_the_run_folder_fuzzers_found_is_refused_naming_the_file(
        run_folder: tuple[Path, dict[str, bytes]], found: str) -> None:
    root, original = run_folder
    name, edit, says = FOUND[found]
    path = root / name
    try:
        edit(path)
        with pytest.raises(ValueError, match=says):
            read_file(root, name)
    finally:
        path.write_bytes(original[name])
