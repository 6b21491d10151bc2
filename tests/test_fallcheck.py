"""The KHR-1HV-like humanoid, its lift demos and the PCA/GPLVM fall check (SPEC §4.3)."""

import numpy as np
import pytest

from latentrl import _native
from latentrl.demos import load_demos
from latentrl.experiments.fallcheck import (
    COLUMNS,
    METHODS,
    FallCheckPreset,
    format_table,
    run_fallcheck,
)
from latentrl.humanoid import GRIP_WIDTH, demos_path, fall_check, hull_margin, model


def test_robot_has_the_documented_size():
    h = model()
    assert len(h.joint_names) == 19
    assert h.joint_names[0] == "head_yaw" and "l_shoulder_pitch" in h.joint_names
    mass = sum(m for _, m, _ in h._inertials)
    assert 1.2 <= mass <= 1.5
    poses = h.on_ground(np.zeros(19))
    assert 0.339 <= poses["head"][2, 3] + 0.06 <= 0.40
    assert np.isclose(min(c[2] for c in h.sole_corners(poses, "l_foot")), 0.0)


@pytest.mark.parametrize("heel, margin", [(False, 0.045), (True, 0.016)])
def test_demos_grip_the_object_and_balance_as_documented(heel, margin):
    h = model()
    X = load_demos(demos_path(heel=heel), expected_joints=h.joint_names).postures
    assert X.shape == (7, 19)
    assert np.all((X >= h.lower) & (X <= h.upper))
    assert np.sum(np.ptp(X, axis=0) > np.radians(10)) >= 10
    for q in X:
        b = h.balance(q)
        assert abs(b["grip_error"]) < 1e-4 and abs(b["margin"] - margin) < 1e-3
        # sagittal: left and right mirror each other
        for joint in ("shoulder_pitch", "elbow", "hip_pitch", "knee", "ankle_pitch"):
            assert q[h.index(f"l_{joint}")] == q[h.index(f"r_{joint}")]
        assert q[h.index("l_shoulder_roll")] == -q[h.index("r_shoulder_roll")]


def test_demo_pose_holds_in_the_sim():
    X = load_demos(demos_path(heel=True)).postures
    out = fall_check(X[0], X[:1], hold=2.0).segments
    assert out.shape == (1, 7)
    fell, min_margin, _, grip, _, base, fall_time = out[0]
    assert fell == 0 and min_margin > 0.01 and abs(grip) < 2e-3 and base > 0.1 and np.isnan(fall_time)


def test_recorded_frames_place_the_robot_where_the_sim_has_it():
    # The recorded base pose and joints, through the NumPy kinematics (independent of rapier),
    # give the support margin and base height the Rust check measured at the end.
    X = load_demos(demos_path(heel=True)).postures
    h = model()
    run = fall_check(X[0], X[:2], hold=0.5, record_times=[0.0, 0.3, 1.0, 5.0])
    assert run.frames.shape == (3, 9 + 19)  # 5 s is past the end: no frame
    np.testing.assert_allclose(run.frames[:, 0], [0.0, 0.3, 1.0], atol=4 / 240)
    assert not run.frames[:, 1].any()
    end = run.link_poses(2)
    corners = np.array([c for s in ("l_foot", "r_foot") for c in h.sole_corners(end, s)])
    touching = corners[corners[:, 2] <= corners[:, 2].min() + 2e-3]
    assert abs(corners[:, 2].min()) < 2e-3  # on the floor
    assert hull_margin(h.com(end)[:2], touching[:, :2]) == pytest.approx(run.segments[1, 2], abs=1e-6)
    assert run.frames[2, 4] == pytest.approx(run.segments[1, 5])
    np.testing.assert_allclose(run.frames[0, 9:], X[0], atol=1e-9)


def test_fall_check_rejects_bad_shapes():
    with pytest.raises(ValueError, match="targets"):
        fall_check(np.zeros(19), np.zeros((2, 18)))
    with pytest.raises(ValueError, match="record_times: expected finite times"):
        fall_check(np.zeros(19), np.zeros((1, 19)), record_times=[float("nan")])
    assert "humanoid_fall_check" in _native.__all__


@pytest.fixture(scope="module")
def table():
    return run_fallcheck(FallCheckPreset(pose_hold=1.0, path_points=4, path_hold=0.2))


def test_table_has_every_method_pose_and_line(table):
    assert all(set(r) == set(COLUMNS) for r in table)
    for method in METHODS:
        rows = [r for r in table if r["method"] == method]
        assert [r["segment"] for r in rows] == [f"pose {i}" for i in range(7)] + [
            "line 0-1", "line 1-2", "line 2-3", "line 4-5", "line 5-6"
        ]
    assert "| PCA | pose 0 |" in format_table(table)


def test_gplvm_keeps_grip_and_margin_of_the_demos(table):
    """SPEC §4.3 acceptance: the GPLVM keeps grip and margin within 1 mm of the demos."""
    demo = {r["segment"]: r for r in table if r["method"] == "joint"}
    demo_margin = min(r["margin"] for s, r in demo.items() if s.startswith("pose"))
    for r in (r for r in table if r["method"] == "GPLVM"):
        assert abs(r["grip_error"]) < 1e-3, r
        if r["segment"].startswith("pose"):
            ref = demo[r["segment"]]
            assert r["rms_deg"] < 0.1 and not r["fell"], r
            assert abs(r["margin"] - ref["margin"]) < 1e-3, r
            assert abs(r["sim_margin"] - ref["sim_margin"]) < 1e-3, r
            assert abs(r["sim_grip_error"] - ref["sim_grip_error"]) < 1e-3, r
        else:  # a latent line within one style stays as balanced as the demos
            assert r["margin"] > demo_margin - 1e-3, r
    # the control: every demo holds
    assert not any(r["fell"] for s, r in demo.items() if s.startswith("pose"))


def test_pca_misses_the_demos_by_degrees(table):
    pca = [r for r in table if r["method"] == "PCA" and r["segment"].startswith("pose")]
    assert max(r["rms_deg"] for r in pca) > 1.0
    assert max(abs(r["grip_error"]) for r in pca) > 5e-3
    assert np.isfinite([r["sim_margin"] for r in pca]).all()  # falls: reported, not asserted
    assert GRIP_WIDTH == 0.10


def test_fig7a_frames_agree_with_the_table(tmp_path):
    pytest.importorskip("matplotlib")
    from latentrl.experiments.fallcheck_figures import fallcheck_frames

    seen = fallcheck_frames(tmp_path, ("pose", 6))
    for ext in ("png", "pdf"):
        assert (tmp_path / f"fig7a.{ext}").stat().st_size > 10_000
    rows = {r["method"]: r for r in run_fallcheck() if r["segment"] == "pose 6"}
    for method in ("PCA", "GPLVM"):
        assert seen[method]["fell"] == rows[method]["fell"]
        assert abs(seen[method]["min_margin"] - rows[method]["sim_margin"]) < 1e-4
    assert seen["PCA"]["fell"] and seen["PCA"]["fall_time"] is not None
    assert not seen["GPLVM"]["fell"] and seen["GPLVM"]["base_height"] > 0.1


@pytest.mark.parametrize("segment", [("pose", 7), ("line", 3), ("curve", 1)])
def test_fig7a_rejects_unknown_segments(tmp_path, segment):
    from latentrl.experiments.fallcheck_figures import fallcheck_frames

    with pytest.raises(ValueError, match="segment must name one of"):
        fallcheck_frames(tmp_path, segment=segment)
    assert not list(tmp_path.iterdir())
