"""An HDF5 file in the robomimic layout as a `Recording`: one group ``data/demo_<i>`` per episode,
the joint positions in ``data/demo_<i>/obs/<key>`` (N, D). Joint names: a ``joint_names``
attribute on that dataset or on ``data``, else given; a demo whose dataset names its joints in
another order is read in the first one's order. Needs h5py (``pip install 'latentrl[hdf5]'``)."""

from __future__ import annotations

import re
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl.recorded.frames import Episode
from latentrl.recorded.libraries import needs

DEFAULT_KEY = "robot0_joint_pos"
DEMO = re.compile(r"demo_(\d+)")
NAMES_ATTRIBUTE = "joint_names"


def _names(value: Any) -> tuple[str, ...]:
    items = np.atleast_1d(np.asarray(value))
    return tuple(item.decode() if isinstance(item, bytes) else str(item) for item in items)


class RobomimicFile:
    """Reads ``data/demo_*/obs/<key>`` (default ``robot0_joint_pos``) of every demo group."""

    def __init__(self, path: Path, key: str | None, joint_names: tuple[str, ...] | None) -> None:
        h5py = needs("h5py", "HDF5", "hdf5")
        self.path, self.field = path, key or DEFAULT_KEY
        try:
            self._file = h5py.File(path, "r")
        except OSError as err:
            raise ValueError(f"{path}: not a readable HDF5 file (cut short?): {err}") from err
        try:
            self.episodes, datasets = self._episodes()
            self.names = joint_names or self._recorded_names(datasets)
            self._order = {} if joint_names else self._orders()
            if datasets and datasets[0].shape[1] != len(self.names):
                raise ValueError(f"{path}: {self.field} has {datasets[0].shape[1]} values per frame, "
                                 f"for {len(self.names)} joint names {list(self.names)}")
        except BaseException:
            self._file.close()
            raise

    def _episodes(self) -> tuple[tuple[Episode, ...], list[Any]]:
        data = self._file.get("data")
        if data is None or not hasattr(data, "keys"):
            raise ValueError(f"{self.path}: no group 'data' (the robomimic layout: data/demo_<i>/obs/<key>)")
        demos = sorted((int(m.group(1)), name) for name in data.keys() if (m := DEMO.fullmatch(name)))
        if not demos:
            raise ValueError(f"{self.path}: no episodes (no data/demo_<i> groups; data has {sorted(data.keys())})")
        twice = [(i, a, b) for (i, a), (j, b) in zip(demos, demos[1:]) if i == j]
        if twice:
            index, first, second = twice[0]
            raise ValueError(f"{self.path}: data/{first} and data/{second} are both episode {index}: rename one")
        self._data: dict[int, Any] = {}
        episodes, width = [], None
        for index, name in demos:
            field = f"data/{name}/obs/{self.field}"
            dataset = self._file.get(field)
            if dataset is None and (link := self._broken_link(field)):
                raise ValueError(f"{self.path}: {link}")
            if dataset is None or not hasattr(dataset, "shape"):
                obs = self._file.get(f"data/{name}/obs")
                keys = sorted(obs.keys()) if obs is not None and hasattr(obs, "keys") else []
                raise ValueError(f"{self.path}: no dataset {field}; data/{name}/obs has {keys} (choose with --demos-key)")
            if len(dataset.shape) != 2 or dataset.dtype.kind not in "iuf":
                raise ValueError(f"{self.path}: {field} is {dataset.dtype} of shape {dataset.shape}, "
                                 "expected numbers (frames, joints)")
            if width is not None and dataset.shape[1] != width:
                raise ValueError(f"{self.path}: {field} has {dataset.shape[1]} values per frame, the episodes "
                                 f"before it {width} (mixed shapes)")
            width = dataset.shape[1]
            self._data[index] = dataset
            episodes.append(Episode(index, dataset.shape[0], f"{self.path}: {field}"))
        return tuple(episodes), [self._data[i] for i, _ in demos]

    def _broken_link(self, field: str) -> str | None:
        """The first link on the way to `field` that leads nowhere (a file moved away), said so."""
        h5py = needs("h5py", "HDF5", "hdf5")
        parts = field.split("/")
        for end in range(1, len(parts) + 1):
            where = "/".join(parts[:end])
            if self._file.get(where) is not None:
                continue
            link = self._file.get(where, getlink=True)
            if isinstance(link, h5py.ExternalLink):
                return f"{where} links to {link.path} in {link.filename}, which cannot be opened (moved or not copied?)"
            if isinstance(link, h5py.SoftLink):
                return f"{where} links to {link.path}, which is not in the file"
            return None
        return None

    def _recorded_names(self, datasets: list[Any]) -> tuple[str, ...]:
        for holder in [*datasets[:1], self._file["data"]]:
            if NAMES_ATTRIBUTE in holder.attrs:
                return _names(holder.attrs[NAMES_ATTRIBUTE])
        raise ValueError(f"{self.path}: no {NAMES_ATTRIBUTE!r} attribute on data/demo_*/obs/{self.field} or data; "
                         "give the joint names (--joint-names a,b,…)")

    def _orders(self) -> dict[int, list[int]]:
        """Per demo whose dataset has its own joint names in another order than `names`, the
        columns that put them in that order; other names are a ValueError naming the demo."""
        orders = {}
        for index, dataset in self._data.items():
            if NAMES_ATTRIBUTE not in dataset.attrs:
                continue
            own = _names(dataset.attrs[NAMES_ATTRIBUTE])
            if own == self.names:
                continue
            if sorted(own) != sorted(self.names) or len(set(own)) != len(own):
                raise ValueError(f"{self.path}: {dataset.name} names its joints {list(own)}, not the recording's "
                                 f"{list(self.names)} in some order")
            orders[index] = [own.index(name) for name in self.names]
        return orders

    def read(self, episode: Episode, step: int) -> NDArray[np.float64]:
        """Every `step`-th frame of the episode's dataset, its columns in the order of `names`."""
        try:
            frames = np.asarray(self._data[episode.index][::step], dtype=np.float64)
            return frames[:, self._order[episode.index]] if episode.index in self._order else frames
        except OSError as err:
            raise ValueError(f"{episode.where}: cannot be read (cut short?): {err}") from err

    def __enter__(self) -> RobomimicFile:
        return self

    def __exit__(self, kind: type[BaseException] | None, err: BaseException | None, tb: TracebackType | None) -> None:
        self._file.close()
