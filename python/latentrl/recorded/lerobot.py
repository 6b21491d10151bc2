"""A LeRobot dataset as a `Recording`: ``meta/info.json`` names the features (the state one's
``names`` are the joints). In the v2.x layout ``data/chunk-*/episode_*.parquet`` hold one episode
each; in the v3.0 layout ``data/chunk-*/file-*.parquet`` hold many, and
``meta/episodes/chunk-*/file-*.parquet`` say which file holds each episode and how many frames it
has (its rows in that file are those of its ``episode_index``). Needs pyarrow
(``pip install 'latentrl[lerobot]'``)."""

from __future__ import annotations

import json
import os
import re
from collections import Counter
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl.recorded.frames import Episode
from latentrl.recorded.libraries import needs

DEFAULT_KEY = "observation.state"
EPISODE_FILE = re.compile(r"episode_(\d+)\.parquet")
V3_EPISODE_COLUMNS = ("episode_index", "data/chunk_index", "data/file_index", "dataset_from_index", "dataset_to_index")
"""The columns of a v3.0 dataset's episode table this reader needs."""
V3_DATA_PATH = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
"""LeRobot v3.0's data file template, when info.json gives none."""


def feature_names(names: Any, where: str) -> tuple[str, ...] | None:
    """A feature's ``names`` in info.json: a list of strings, or a dict with one such list (v2.0's
    ``{"motors": [...]}``); None where there are none."""
    if names is None:
        return None
    if isinstance(names, dict) and len(names) == 1:
        names = next(iter(names.values()))
    if isinstance(names, list) and all(isinstance(n, str) for n in names):
        return tuple(names)
    raise ValueError(f"{where}: names {names!r} are not a list of joint names")


class LeRobotDataset:
    """Reads the feature `key` (default ``observation.state``) of every episode's parquet file."""

    def __init__(self, path: Path, key: str | None, joint_names: tuple[str, ...] | None) -> None:
        self._pa = needs("pyarrow", "a LeRobot dataset", "lerobot")
        self._pq = needs("pyarrow.parquet", "a LeRobot dataset", "lerobot")
        self._pc = needs("pyarrow.compute", "a LeRobot dataset", "lerobot")
        self.path, self.field = path, key or DEFAULT_KEY
        info_path = path / "meta" / "info.json"
        try:
            info = json.loads(info_path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError) as err:
            raise ValueError(f"{info_path}: not valid JSON ({err})") from err
        features = info.get("features") if isinstance(info, dict) else None
        if not isinstance(features, dict):
            raise ValueError(f"{info_path}: no features (a LeRobot info.json has a features table)")
        self._v3 = str(info.get("codebase_version", "v2")).startswith("v3")
        self._files: dict[int, Path] = {}  # episode index → its data file
        self._table: tuple[Path, Any] | None = None  # the last data file read (a v3.0 file holds many episodes)
        feature = features.get(self.field)
        if not isinstance(feature, dict):
            vectors = sorted(k for k, v in features.items() if isinstance(v, dict) and v.get("dtype") in ("float32", "float64"))
            raise ValueError(f"{info_path}: no feature {self.field!r}; its float features are {vectors} "
                             "(choose one with --demos-key)")
        where = f"{info_path}: features.{self.field}"
        names = joint_names or feature_names(feature.get("names"), where)
        if names is None:
            raise ValueError(f"{where} has no names; give the joint names (--joint-names a,b,…)")
        shape = feature.get("shape")
        if shape is not None and list(shape) != [len(names)]:
            raise ValueError(f"{where}: shape {shape} for {len(names)} joint names {list(names)}")
        self.names = names
        self.episodes = self._v3_episodes(info, info_path) if self._v3 else self._episodes(info, info_path)

    def _episodes(self, info: dict[str, Any], info_path: Path) -> tuple[Episode, ...]:
        files = {}
        for file in sorted(self.path.glob("data/chunk-*/episode_*.parquet")):
            match = EPISODE_FILE.fullmatch(file.name)
            if match:
                files[int(match.group(1))] = file
        expected = info.get("total_episodes")
        if isinstance(expected, int) and expected != len(files):
            raise ValueError(f"{info_path}: total_episodes is {expected}, but {self.path / 'data'} holds {len(files)} "
                             "episode files (data/chunk-*/episode_*.parquet)")
        episodes = []
        for index, file in sorted(files.items()):
            parquet = self._open(file)
            if parquet.schema_arrow.get_field_index(self.field) < 0:
                raise ValueError(f"{file}: no column {self.field!r}; it has {parquet.schema_arrow.names}")
            episodes.append(Episode(index, parquet.metadata.num_rows, str(file)))
            self._files[index] = file
        return tuple(episodes)

    def _v3_episodes(self, info: dict[str, Any], info_path: Path) -> tuple[Episode, ...]:
        """The episodes of a v3.0 dataset from its episode table, each with its data file."""
        template, checked, episodes = info.get("data_path") or V3_DATA_PATH, set(), []
        for row in sorted(self._episode_table(info, info_path), key=lambda r: r["episode_index"]):
            index = row["episode_index"]
            try:
                file = self.path / template.format(chunk_index=row["data/chunk_index"], file_index=row["data/file_index"])
            except (KeyError, IndexError, ValueError, TypeError) as err:
                raise ValueError(f"{info_path}: data_path {template!r} is no v3 data file template ({err!r})") from err
            # Lexically, not resolved: the Hugging Face cache links every file to a blob outside the folder.
            if not Path(os.path.normpath(file)).is_relative_to(os.path.normpath(self.path)):
                raise ValueError(f"{info_path}: data_path {template!r} leads out of the dataset, to {file}")
            if file not in checked:
                if not file.is_file():
                    raise ValueError(f"{self.path}: episode {index}'s data file {file} is missing")
                schema = self._open(file).schema_arrow
                missing = [c for c in (self.field, "episode_index") if schema.get_field_index(c) < 0]
                if missing:
                    raise ValueError(f"{file}: no column {missing[0]!r}; it has {schema.names}")
                checked.add(file)
            self._files[index] = file
            episodes.append(Episode(index, row["dataset_to_index"] - row["dataset_from_index"], str(file)))
        return tuple(episodes)

    def _episode_table(self, info: dict[str, Any], info_path: Path) -> list[dict[str, Any]]:
        """The rows of a v3.0 dataset's episode table (its files in order), checked: the columns
        this reader needs, integers, each episode once, as many as `total_episodes`."""
        tables = sorted(self.path.glob("meta/episodes/chunk-*/file-*.parquet"))
        if not tables:
            raise ValueError(f"{info_path}: a LeRobot v3 dataset without its episode table "
                             f"({self.path / 'meta/episodes/chunk-*/file-*.parquet'})")
        rows: list[dict[str, Any]] = []
        for table in tables:
            parquet = self._open(table)
            missing = [c for c in V3_EPISODE_COLUMNS if c not in parquet.schema_arrow.names]
            if missing:
                raise ValueError(f"{table}: no columns {missing} (a LeRobot v3 episode table has {list(V3_EPISODE_COLUMNS)})")
            rows += parquet.read(columns=list(V3_EPISODE_COLUMNS)).to_pylist()
        expected = info.get("total_episodes")
        if isinstance(expected, int) and expected != len(rows):
            raise ValueError(f"{info_path}: total_episodes is {expected}, but its episode table lists {len(rows)}")
        for row in rows:
            bad = [c for c in V3_EPISODE_COLUMNS if not (isinstance(row[c], int) and row[c] >= 0)]
            if bad or row["dataset_to_index"] < row["dataset_from_index"]:
                raise ValueError(f"{tables[0].parent.parent}: episode table row {row}: "
                                 + (f"{bad} must be integers >= 0" if bad else "dataset_to_index is below dataset_from_index"))
        repeated = sorted(i for i, n in Counter(r["episode_index"] for r in rows).items() if n > 1)
        if repeated:
            raise ValueError(f"{tables[0].parent.parent}: the episode table lists episodes {repeated} more than once")
        return rows

    def _open(self, file: Path) -> Any:
        try:
            return self._pq.ParquetFile(file)
        except (self._pa.ArrowException, OSError) as err:
            raise ValueError(f"{file}: not a readable parquet file (cut short?): {err}") from err

    def read(self, episode: Episode, step: int) -> NDArray[np.float64]:
        """Every `step`-th frame of the episode's state column; a frame whose length is not the
        number of joints is a ValueError naming the file, column and frame."""
        where = f"{episode.where}: {f'episode {episode.index}, ' if self._v3 else ''}column {self.field!r}"
        column = self._column(episode, where)
        if len(self.names) == 1 and (self._pa.types.is_floating(column.type) or self._pa.types.is_integer(column.type)):
            if column.null_count:  # LeRobot writes a one-value feature as a plain column
                raise ValueError(f"{where}: frame {column.is_null().index(True).as_py()} has no value")
            return np.asarray(column.to_numpy(zero_copy_only=False), dtype=np.float64)[::step, None]
        if not self._pa.types.is_list(column.type) and not self._pa.types.is_fixed_size_list(column.type) \
                and not self._pa.types.is_large_list(column.type):
            raise ValueError(f"{where}: holds {column.type}, not a list of joint values per frame")
        lengths = self._pc.list_value_length(column).to_numpy(zero_copy_only=False)
        odd = np.flatnonzero(~(lengths == len(self.names)))  # a null frame's length is NaN
        if odd.size:
            found = "no value" if np.isnan(lengths[odd[0]]) else f"{lengths[odd[0]]:g} values"
            raise ValueError(f"{where}: frame {odd[0]} has {found}, expected {len(self.names)} "
                             f"(one per joint: {list(self.names)})")
        values = np.asarray(column.flatten().to_numpy(zero_copy_only=False), dtype=np.float64)
        return values.reshape(len(column), len(self.names))[::step]

    def _column(self, episode: Episode, where: str) -> Any:
        """The episode's state column: its file's (v2.x), or its rows of its file's (v3.0), which
        must be as many as the episode table gives."""
        file = self._files[episode.index]
        columns = [self.field, "episode_index"] if self._v3 else [self.field]
        try:
            if self._table is None or self._table[0] != file:
                self._table = (file, self._open(file).read(columns=columns))
            table = self._table[1]
            if not self._v3:
                return table.column(0).combine_chunks()
            rows = np.flatnonzero(table.column(1).to_numpy(zero_copy_only=False) == episode.index)
        except self._pa.ArrowException as err:
            raise ValueError(f"{where}: cannot be read (cut short?): {err}") from err
        if len(rows) != episode.frames:
            raise ValueError(f"{episode.where}: {len(rows)} rows of episode_index {episode.index}, where the episode "
                             f"table gives {episode.frames} frames")
        return table.column(0).take(rows).combine_chunks()

    def __enter__(self) -> LeRobotDataset:
        return self

    def __exit__(self, kind: type[BaseException] | None, err: BaseException | None, tb: TracebackType | None) -> None:
        return None
