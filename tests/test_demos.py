import json
from pathlib import Path
from unittest.mock import patch

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import latentrl.demos
from latentrl import Demonstrations, load_demos, save_demos

NAMES = ("shoulder_l", "elbow_l", "shoulder_r", "elbow_r")


def demos(n=5):
    return Demonstrations(np.random.default_rng(0).normal(size=(n, 4)), NAMES)


@pytest.mark.parametrize("suffix", [".csv", ".npz", ".json"])
def test_round_trip_is_exact(tmp_path, suffix):
    original = demos()
    save_demos(original, tmp_path / f"demos{suffix}")
    loaded = load_demos(tmp_path / f"demos{suffix}")
    np.testing.assert_array_equal(loaded.postures, original.postures)
    assert loaded.joint_names == NAMES
    assert [p.name for p in tmp_path.iterdir()] == [f"demos{suffix}"]  # no temporary file left


@given(
    arrays(
        np.float64,
        st.tuples(st.integers(1, 4), st.integers(1, 3)),
        elements=st.floats(-1e300, 1e300),
    )
)
def test_round_trip_any_finite_values(tmp_path_factory, postures):
    directory = tmp_path_factory.mktemp("rt")
    names = tuple(f"j,{i}" for i in range(postures.shape[1]))  # a comma, quoted in CSV
    for suffix in (".csv", ".json", ".npz"):
        save_demos(Demonstrations(postures, names), directory / f"d{suffix}")
        loaded = load_demos(directory / f"d{suffix}")
        np.testing.assert_array_equal(loaded.postures, postures)
        assert loaded.joint_names == names


def test_postures_are_a_read_only_copy():
    source = np.zeros((2, 4))
    d = Demonstrations(source, list(NAMES))
    source[0, 0] = 1.0
    assert d.postures[0, 0] == 0.0 and isinstance(d.joint_names, tuple)
    with pytest.raises(ValueError, match="read-only"):
        d.postures[0, 0] = 2.0
    assert repr(d) == f"Demonstrations(2 postures of {list(NAMES)})"


def test_expected_joints_reorder_columns(tmp_path):
    save_demos(demos(), tmp_path / "d.csv")
    reordered = load_demos(tmp_path / "d.csv", expected_joints=NAMES[::-1])
    assert reordered.joint_names == NAMES[::-1]
    np.testing.assert_array_equal(reordered.postures, demos().postures[:, ::-1])


def test_csv_with_byte_order_mark_and_spaces(tmp_path):
    path = tmp_path / "excel.csv"
    path.write_bytes("\ufeffa, b\n1, 2.5\n".encode())
    loaded = load_demos(path)
    assert loaded.joint_names == ("a", "b")
    np.testing.assert_array_equal(loaded.postures, [[1.0, 2.5]])


@given(
    st.lists(st.lists(st.floats(-1e300, 1e300), min_size=3, max_size=3), min_size=1,
             max_size=4),
    st.sampled_from(["{!r}", "{:.3e}", " {:.17g} ", "{:+.1f}\t"]),
    st.sampled_from(["\n", "\r\n"]),
    st.sampled_from(["", "\n", "\n\n"]),
)
def test_numpy_reads_a_plain_csv_as_the_cell_by_cell_reader(tmp_path_factory, rows, cell, eol, end):
    path = tmp_path_factory.mktemp("csv") / "d.csv"
    path.write_bytes((eol.join(["a, b ,c", *(",".join(cell.format(v) for v in row) for row in rows)]) + end).encode())
    fast = load_demos(path)
    with patch.object(latentrl.demos, "_numbers_below_header", lambda text, joint_map: None):
        cells = load_demos(path)
    np.testing.assert_array_equal(fast.postures, cells.postures)
    assert fast.joint_names == cells.joint_names == ("a", "b", "c")


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("name", "text", "match"),
    [
        ("d.csv", "", "empty file"),
        ("d.csv", "\n\n", "empty file"),
        ("d.csv", "a,b\n", "at least one posture"),
        ("d.csv", "a,b\n1,2\n3\n", r"line 3 \(posture 1\): 1 values, expected 2"),
        ("d.csv", "a,b\n1,2\n3,x\n", r"line 3 \(posture 1\), joint 'b': 'x' is not a number"),
        ("d.csv", "a,b\n1,2\n3,0_5\n", r"line 3 \(posture 1\), joint 'b': '0_5' is not a number"),  # float() reads 5
        ("d.csv", "1,2\n3,4\n", "line 1 holds numbers, not joint names: the first row must name the joints"),
        ("d.csv", "# rec\n1,2\n3,4\n", "line 2 holds numbers, not joint names"),
        ("d.csv", "a;b\n1;2\n", "line 1 is one column, 'a;b': the file is separated by ';', not by commas"),
        ("d.csv", "a\tb\n1\t2\n", "separated by '\\\\t', not by commas"),
        ("d.csv", "a,b\n1,2\n3,nan\n", "posture 1, joint 'b': non-finite value nan"),
        ("d.csv", "a,b\ninf,2\n", "posture 0, joint 'a': non-finite value inf"),
        ("d.csv", "a,b,a\n1,2,3\n", r"duplicate joint names \['a'\]"),
        ("d.csv", "a,,c\n1,2,3\n", r"column 2 has no name in the header but values \(line 2 \(posture 0\): '2'\): "
                                   r"name it in the header \(a joint, or a column to leave out with --joint-map NAME= "
                                   r"\(joint_map=\{'NAME': ''\}\)\)"),
        ("d.json", "{", "not valid JSON"),
        ("d.json", '{"postures": [[1]]}', 'keys "joint_names" and "postures"'),
        ("d.json", '{"joint_names": ["a"], "postures": 1}', "must be lists"),
        (
            "d.json",
            '{"joint_names": ["a", "b"], "postures": [[1, 2], [3]]}',
            "posture 1: 1 values, expected 2",
        ),
        (
            "d.json",
            '{"joint_names": ["a", "b"], "postures": [[1, 2], 3]}',
            "posture 1: expected a list",
        ),
        (
            "d.json",
            '{"joint_names": ["a"], "postures": [[true]]}',
            "posture 0, joint 'a': True is not a number",
        ),
        (
            "d.json",
            '{"joint_names": ["a"], "postures": [[null]]}',
            "posture 0, joint 'a': None is not a number",
        ),
        (
            "d.json",
            '{"joint_names": ["a"], "postures": [[NaN]]}',
            "posture 0, joint 'a': non-finite value nan",
        ),
        (
            "d.json",
            '{"joint_names": ["a", 2], "postures": [[1, 2]]}',
            "every name must be a non-empty string",
        ),
        ("d.npz", "not a zip", "not a readable NPZ file"),
        ("d.txt", "a,b\n1,2\n", "unsupported extension '.txt'; expected one of .csv, .json, .npz"),
    ],
)
def test_bad_files_name_the_problem(tmp_path, name, text, match):
    path = write(tmp_path, name, text)
    with pytest.raises(ValueError, match=match) as info:
        load_demos(path)
    assert str(path) in str(info.value)


def test_bad_npz_contents(tmp_path):
    np.savez(tmp_path / "missing.npz", postures=np.ones((2, 2)))
    with pytest.raises(ValueError, match=r"missing arrays \['joint_names'\]"):
        load_demos(tmp_path / "missing.npz")
    np.savez(
        tmp_path / "text.npz", postures=np.array([["a", "b"]]), joint_names=np.array(["a", "b"])
    )
    with pytest.raises(ValueError, match="postures: expected numbers, got dtype <U1"):
        load_demos(tmp_path / "text.npz")
    np.savez(tmp_path / "names.npz", postures=np.ones((1, 2)), joint_names=np.array([1, 2]))
    with pytest.raises(ValueError, match="joint_names: expected a 1-D array of strings"):
        load_demos(tmp_path / "names.npz")
    np.savez(tmp_path / "shape.npz", postures=np.ones((2, 3)), joint_names=np.array(["a", "b"]))
    with pytest.raises(ValueError, match="postures: 3 columns for 2 joint names"):
        load_demos(tmp_path / "shape.npz")


def test_expected_joints_and_min_postures(tmp_path):
    path = write(tmp_path, "d.csv", "a,b,c\n1,2,3\n4,5,6\n")
    with pytest.raises(ValueError, match=r"missing \['d'\], unknown \['c'\]"):
        load_demos(path, expected_joints=["a", "b", "d"])
    with pytest.raises(ValueError, match=r"missing \[\], unknown \['c'\]"):
        load_demos(path, expected_joints=["a", "b"])
    with pytest.raises(ValueError, match="2 postures, expected at least 3"):
        load_demos(path, min_postures=3)
    assert load_demos(path, min_postures=2).postures.shape == (2, 3)
    with pytest.raises(FileNotFoundError):
        load_demos(tmp_path / "absent.csv")


def test_save_rejects_unknown_extension_and_keeps_the_old_file_on_failure(tmp_path, monkeypatch):
    with pytest.raises(ValueError, match=r"unsupported extension '\.yaml'"):
        save_demos(demos(), tmp_path / "d.yaml")
    path = tmp_path / "d.json"
    save_demos(demos(2), path)
    before = path.read_bytes()

    def fail(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(json, "dumps", fail)
    with pytest.raises(RuntimeError, match="disk full"):
        save_demos(demos(7), path)
    assert path.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["d.json"]


def test_a_csv_that_is_not_utf8_is_refused_naming_its_line(tmp_path):
    """A Latin-1 CSV (a spreadsheet's export) said "'utf-8' codec can't decode byte 0xe9 in
    position 32", a byte offset; a byte-order mark and CRLF line ends are read as before."""
    text = "a,b\r\n0.1,0.2\r\n0.3,0.4\r\n"
    (tmp_path / "latin1.csv").write_bytes(text.encode() + "0.5,0.6 # café\r\n".encode("latin-1"))
    with pytest.raises(ValueError, match=r"latin1.csv: is not UTF-8 text \(line 4 has byte 0xe9\); save it as UTF-8"):
        load_demos(tmp_path / "latin1.csv")
    (tmp_path / "bom.csv").write_bytes(b"\xef\xbb\xbf" + text.encode())
    demos = load_demos(tmp_path / "bom.csv")
    assert demos.joint_names == ("a", "b") and demos.postures.tolist() == [[0.1, 0.2], [0.3, 0.4]]


def test_a_recorders_comments_above_the_header_are_skipped(tmp_path):
    """A '# comment' first line was taken for the header: "line 2 (posture 0): 3 values, expected 1"."""
    (tmp_path / "d.csv").write_text("# recorded 2026-12-06\n  # arm 2\na,b,c\n0.1,0.2,0.3\n0.4,0.5,0.6\n")
    demos = load_demos(tmp_path / "d.csv")
    assert demos.joint_names == ("a", "b", "c")
    np.testing.assert_array_equal(demos.postures, [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]])


def test_max_postures_below_what_a_fit_needs_is_named(tmp_path):
    """It said "demos.csv: 2 postures, expected at least 3", blaming the file."""
    save_demos(Demonstrations(np.arange(12.0).reshape(4, 3), ("a", "b", "c")), tmp_path / "d.csv")
    with pytest.raises(ValueError, match=r"max_postures \(--max-postures\) = 2 keeps fewer postures than the 3"):
        load_demos(tmp_path / "d.csv", max_postures=2, min_postures=3)


@pytest.mark.parametrize("fast", [True, False])
def test_columns_the_joint_map_leaves_out_are_never_parsed(tmp_path, fast):
    """A time stamp, a gripper's state in words, a ROS export's empty frame id: mapped to nothing
    (`--joint-map stamp=`), they said "joint 'stamp': '2024-05-01T12:00:00.000' is not a number"."""
    path = write(tmp_path, "d.csv", "stamp,a,gripper,frame_id,b\n"
                                    "2024-05-01T12:00:00.000,0.1,open,,0.2\n2024-05-01T12:00:01.001,0.3,closed,,0.4\n")
    drop = {"stamp": "", "gripper": "", "frame_id": ""}
    with patch.object(latentrl.demos, "_numbers_below_header", latentrl.demos._numbers_below_header if fast
                      else lambda text, joint_map: None):
        demos = load_demos(path, joint_map=drop)
        assert demos.joint_names == ("a", "b") and demos.postures.tolist() == [[0.1, 0.2], [0.3, 0.4]]
        with pytest.raises(ValueError, match=r"line 2 \(posture 0\), joint 'stamp': '2024-05-01T12:00:00.000' is not"):
            load_demos(path, joint_map={"gripper": "", "frame_id": ""})  # a kept column is still named
        write(tmp_path, "ragged.csv", "stamp,a,b\nx,0.1,0.2\ny,0.3,0.4,0.5\n")
        with pytest.raises(ValueError, match=r"line 3 \(posture 1\): 4 values, expected 3"):
            load_demos(tmp_path / "ragged.csv", joint_map={"stamp": ""})


def test_a_column_of_text_is_refused_with_how_to_leave_it_out(tmp_path):
    """A time stamp column (`latentrl check` of a recorder's CSV) said only "joint 'timestamp':
    '2026-…' is not a number", where a numeric column that is no joint of the robot is told how
    to leave it out (`--joint-map NAME=`). A bad value in a column of numbers is not."""
    from latentrl import Task

    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    rows = (example / "demos.csv").read_text().splitlines()
    path = write(tmp_path, "d.csv", "\n".join([f"timestamp,{rows[0]}"] + [f"2026-12-07T00:00:{i:02d}.000,{row}"
                                                                         for i, row in enumerate(rows[1:])]) + "\n")
    with pytest.raises(ValueError, match=r"line 2 \(posture 0\), joint 'timestamp': '2026-12-07T00:00:00.000' is not "
                                         r"a number; column 'timestamp' holds no number: a column that is no joint is "
                                         r"left out with --joint-map timestamp= \(joint_map=\{'timestamp': ''\}\)"):
        Task.load(example / "glass_arm.toml").demos(path)
    with pytest.raises(ValueError, match=r"joint 'b': 'x' is not a number$"):
        load_demos(write(tmp_path, "typo.csv", "a,b\n0.1,0.2\n0.3,x\n"))


def test_an_empty_unnamed_column_is_absent_and_a_dataframe_index_is_named(tmp_path):
    """A trailing comma on every line said "joint '': '' is not a number"; a pandas index column
    "joint_names: every name must be a non-empty string"."""
    trailing = load_demos(write(tmp_path, "d.csv", "a,b,\n0.1,0.2,\n0.3,0.4,\n"))
    assert trailing.joint_names == ("a", "b") and trailing.postures.tolist() == [[0.1, 0.2], [0.3, 0.4]]
    with pytest.raises(ValueError, match=r"d.csv: column 1 has no name in the header but values \(line 2 \(posture "
                                         r"0\): '0'\): it looks like a DataFrame's index written with the CSV; write "
                                         r"it with to_csv\(index=False\)"):
        load_demos(write(tmp_path, "d.csv", ",a,b\n0,0.1,0.2\n1,0.3,0.4\n"))
