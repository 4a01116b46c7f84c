"""A LeRobot v3.0 dataset writer (the on-disk format of the ``lerobot`` library, 0.4 and later).

Written with pyarrow and imageio's ffmpeg, without the ``lerobot`` library (which pins torch):
``meta/info.json``, ``meta/stats.json``, ``meta/tasks.parquet``,
``meta/episodes/chunk-000/file-000.parquet``, ``data/chunk-000/file-000.parquet`` (every episode's
frames) and one H.264 MP4 per episode and camera, ``videos/{key}/chunk-CCC/file-FFF.mp4`` (each
episode's rows name its file and its from/to timestamps, as v3.0 allows). Features follow
``lerobot``: ``{"dtype", "shape", "names"}``, shape ``(1,)`` stored as a scalar column, the
default columns ``timestamp``, ``frame_index``, ``episode_index``, ``index``, ``task_index``.

Every saved episode is on disk at once: :meth:`DatasetWriter.checkpoint` rewrites the metadata
and data files (each through a temporary file renamed over it), so that an interrupted writer
leaves a dataset of the episodes it saved, which :meth:`DatasetWriter.resume` takes up again.
The episode being written lives under ``tmp/`` until it is saved; a resumed writer removes it.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np

CODEBASE_VERSION = "v3.0"
CHUNK_SIZE = 1000
DATA_PATH = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
VIDEO_PATH = "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4"
EPISODES_PATH = "meta/episodes/chunk-000/file-000.parquet"
DEFAULT_FEATURES = {
    "timestamp": {"dtype": "float32", "shape": [1], "names": None},
    "frame_index": {"dtype": "int64", "shape": [1], "names": None},
    "episode_index": {"dtype": "int64", "shape": [1], "names": None},
    "index": {"dtype": "int64", "shape": [1], "names": None},
    "task_index": {"dtype": "int64", "shape": [1], "names": None},
}
QUANTILES = (0.01, 0.10, 0.50, 0.90, 0.99)
#: The saved episodes' image samples (the image statistics), kept so that a resumed writer can
#: compute them again; not a lerobot file.
SAMPLES_PATH = "meta/agentchord_image_samples.npz"


class DatasetWriter:
    """Write episodes frame by frame; :meth:`save_episode` keeps one, :meth:`discard_episode` drops it.

    Args:
        root: The dataset's directory (must not exist yet, as ``lerobot`` requires).
        fps: Frames per second.
        features: User features, ``{name: {"dtype", "shape", "names"}}``; dtype ``video`` for
            camera images (shape [H, W, 3]).
        robot_type: ``info.json``'s robot type.

    Raises:
        FileExistsError: ``root`` exists.
    """

    def __init__(self, root: str | Path, fps: int, features: dict, robot_type: str = "aloha", *, exist_ok: bool = False) -> None:
        self.root = Path(root)
        self.root.mkdir(parents=True, exist_ok=exist_ok)
        self.fps = fps
        self.features = {k: {**v, "shape": list(v["shape"])} for k, v in features.items()}
        self.robot_type = robot_type
        self.video_keys = [k for k, v in self.features.items() if v["dtype"] == "video"]
        self.tasks: dict[str, int] = {}
        self.episodes: list[dict] = []
        self.columns: dict[str, list] = {k: [] for k in (*self._data_keys(), *DEFAULT_FEATURES)}
        self._buffer: dict[str, list] = {}
        self._writers: dict = {}
        self._episode_video: dict[str, Path] = {}
        #: Per camera, pixel samples of the saved episodes (the image statistics).
        self._samples: dict[str, list[np.ndarray]] = {k: [] for k in self.video_keys}
        self._new_episode()

    @classmethod
    def resume(cls, root: str | Path, fps: int, features: dict, episodes: int, robot_type: str = "aloha") -> DatasetWriter:
        """A writer that goes on with the first ``episodes`` saved episodes of the dataset at ``root``.

        Files a writer interrupted during a checkpoint may have written for a later episode are
        ignored (and overwritten as it goes on); the unsaved episode under ``tmp/`` is removed.

        Raises:
            ValueError: The dataset's features or fps differ, or it holds fewer episodes.
            OSError: A file cannot be read.
        """
        import pyarrow.parquet as pq

        writer = cls(root, fps, features, robot_type, exist_ok=True)
        shutil.rmtree(writer.root / "tmp", ignore_errors=True)
        for key in writer.video_keys:  # an episode whose video was moved in before the checkpoint that kept it
            for path in (writer.root / "videos" / key).glob("chunk-*/file-*.mp4"):
                chunk, file = int(path.parent.name[6:]), int(path.stem[5:])
                if chunk * CHUNK_SIZE + file >= episodes:
                    path.unlink()
        info = json.loads((writer.root / "meta/info.json").read_text())
        if info.get("fps") != fps or info.get("features") != {**writer.features, **DEFAULT_FEATURES}:
            raise ValueError("its frame rate or features (cameras, image size, objects) differ")
        if episodes == 0:
            return writer
        rows = pq.read_table(writer.root / EPISODES_PATH).to_pylist()
        if len(rows) < episodes:
            raise ValueError(f"meta/episodes holds {len(rows)} episodes, not the {episodes} recorded")
        writer.episodes = rows[:episodes]
        frames = writer.episodes[-1]["dataset_to_index"]
        table = pq.read_table(writer.root / DATA_PATH.format(chunk_index=0, file_index=0)).slice(0, frames)
        data = table.to_pydict()
        for key in writer.columns:
            writer.columns[key] = list(data[key])
        tasks = pq.read_table(writer.root / "meta/tasks.parquet").to_pydict()
        writer.tasks = {t: int(i) for t, i in zip(tasks["__index_level_0__"], tasks["task_index"])}
        samples = writer.root / SAMPLES_PATH
        if writer.video_keys and samples.exists():
            with np.load(samples) as stored:
                for key in writer.video_keys:
                    parts = [stored[f"{key}/{k}"] for k in range(episodes) if f"{key}/{k}" in stored]
                    writer._samples[key] = parts
        return writer

    def _data_keys(self) -> list[str]:
        return [k for k in self.features if k not in self.video_keys]

    def _new_episode(self) -> None:
        self._buffer = {k: [] for k in self._data_keys()}
        self._writers = {}
        self._episode_video = {}
        self._episode_samples: dict[str, list[np.ndarray]] = {k: [] for k in self.video_keys}

    @property
    def total_frames(self) -> int:
        """Frames of the episodes saved so far."""
        return len(self.columns["index"])

    def add_frame(self, frame: dict) -> None:
        """One frame: a value per user feature (images as (H, W, 3) uint8)."""
        import imageio.v2 as imageio

        for key in self._data_keys():
            self._buffer[key].append(frame[key])
        for key in self.video_keys:
            image = np.asarray(frame[key], dtype=np.uint8)
            writer = self._writers.get(key)
            if writer is None:
                path = self.root / "tmp" / f"{key}.mp4"
                path.parent.mkdir(parents=True, exist_ok=True)
                writer = imageio.get_writer(path, fps=self.fps, codec="libx264", quality=8, macro_block_size=8,
                                            pixelformat="yuv420p", ffmpeg_log_level="error")
                self._writers[key] = writer
                self._episode_video[key] = path
            writer.append_data(image)
            if self.episode_frames % 10 == 1:  # every 10th frame, every 8th pixel: the image statistics
                self._episode_samples[key].append(image[::8, ::8].reshape(-1, 3))

    @property
    def episode_frames(self) -> int:
        """Frames added to the episode being written."""
        return len(next(iter(self._buffer.values()))) if self._buffer else 0

    def discard_episode(self) -> None:
        """Drop the episode being written."""
        for writer in self._writers.values():
            writer.close()
        for path in self._episode_video.values():
            path.unlink(missing_ok=True)
        self._new_episode()

    def save_episode(self, task: str, extra: dict | None = None) -> int:
        """Keep the episode being written, with its task (the instruction); returns its index.

        Args:
            task: The episode's task text.
            extra: More columns of its row in ``meta/episodes`` (seed, outcome ...).
        """
        length = self.episode_frames
        if length == 0:
            raise ValueError("no frames added to this episode")
        index = len(self.episodes)
        task_index = self.tasks.setdefault(task, len(self.tasks))
        start = self.total_frames
        for key in self._data_keys():
            self.columns[key].extend(self._buffer[key])
        self.columns["timestamp"].extend((np.arange(length) / self.fps).astype(np.float32).tolist())
        self.columns["frame_index"].extend(range(length))
        self.columns["episode_index"].extend([index] * length)
        self.columns["index"].extend(range(start, start + length))
        self.columns["task_index"].extend([task_index] * length)
        chunk, file = divmod(index, CHUNK_SIZE)
        row = {
            "episode_index": index,
            "tasks": [task],
            "length": length,
            "data/chunk_index": 0,
            "data/file_index": 0,
            "dataset_from_index": start,
            "dataset_to_index": start + length,
        }
        for key in self.video_keys:
            self._writers[key].close()
            target = self.root / VIDEO_PATH.format(video_key=key, chunk_index=chunk, file_index=file)
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(self._episode_video[key], target)
            row.update({f"videos/{key}/chunk_index": chunk, f"videos/{key}/file_index": file,
                        f"videos/{key}/from_timestamp": 0.0, f"videos/{key}/to_timestamp": length / self.fps})
        row.update({"meta/episodes/chunk_index": 0, "meta/episodes/file_index": 0})
        for key in self._data_keys():
            stats = _stats(self._buffer[key], self.features[key])
            for name, value in (stats or {}).items():
                row[f"stats/{key}/{name}"] = value
        for key in self.video_keys:  # one array per episode (saved beside the dataset for a resumed writer)
            parts = self._episode_samples[key]
            self._samples[key].append(np.concatenate(parts) if parts else np.zeros((0, 3), np.uint8))
        row.update(extra or {})
        self.episodes.append(row)
        self._new_episode()
        return index

    def finalize(self) -> Path:
        """Drop an unsaved episode and write every file of the saved ones; returns the root."""
        self.discard_episode()
        shutil.rmtree(self.root / "tmp", ignore_errors=True)
        return self.checkpoint()

    def checkpoint(self) -> Path:
        """Write the data, episodes, tasks, stats and info files of the episodes saved so far.

        Each file is written to a temporary file and renamed over the old one, ``info.json`` last.
        """
        import pyarrow as pa
        import pyarrow.parquet as pq

        (self.root / "meta").mkdir(exist_ok=True)
        features = {**self.features, **DEFAULT_FEATURES}
        if self.episodes:
            arrays = {key: _arrow_column(self.columns[key], features[key]) for key in self.columns}
            _atomic(self.root / DATA_PATH.format(chunk_index=0, file_index=0), lambda p: pq.write_table(pa.table(arrays), p))
            keys = list(dict.fromkeys(k for row in self.episodes for k in row))
            episodes = pa.table({k: pa.array([row.get(k) for row in self.episodes]) for k in keys})
            _atomic(self.root / EPISODES_PATH, lambda p: pq.write_table(episodes, p))
            if self.video_keys:
                samples = {f"{key}/{k}": part for key in self.video_keys for k, part in enumerate(self._samples[key])}
                _atomic(self.root / SAMPLES_PATH, lambda p: np.savez(p, **samples), suffix=".npz")
        self._write_tasks()
        stats = {key: _stats(self.columns[key], features[key]) for key in self.columns}
        for key in self.video_keys:
            stats[key] = _video_stats(self._samples[key])
        _write_json(self.root / "meta/stats.json", {k: v for k, v in stats.items() if v})
        info = {
            "codebase_version": CODEBASE_VERSION,
            "robot_type": self.robot_type,
            "total_episodes": len(self.episodes),
            "total_frames": self.total_frames,
            "total_tasks": len(self.tasks),
            "chunks_size": CHUNK_SIZE,
            "data_files_size_in_mb": 100,
            "video_files_size_in_mb": 500,
            "fps": self.fps,
            "splits": {"train": f"0:{len(self.episodes)}"},
            "data_path": DATA_PATH,
            "video_path": VIDEO_PATH if self.video_keys else None,
            "features": features,
        }
        _write_json(self.root / "meta/info.json", info)
        return self.root

    def _write_tasks(self) -> None:
        """``meta/tasks.parquet``: the task texts as the (pandas) index, their ``task_index`` column."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        tasks = sorted(self.tasks, key=self.tasks.get)
        table = pa.table({"task_index": pa.array([self.tasks[t] for t in tasks], pa.int64()),
                          "__index_level_0__": pa.array(tasks, pa.string())})
        pandas_meta = {
            "index_columns": ["__index_level_0__"], "column_indexes": [],
            "columns": [
                {"name": "task_index", "field_name": "task_index", "pandas_type": "int64", "numpy_type": "int64", "metadata": None},
                {"name": None, "field_name": "__index_level_0__", "pandas_type": "unicode", "numpy_type": "object", "metadata": None},
            ],
            "creator": {"library": "pyarrow", "version": pa.__version__}, "pandas_version": "2.2.0",
        }
        table = table.replace_schema_metadata({b"pandas": json.dumps(pandas_meta).encode()})
        _atomic(self.root / "meta/tasks.parquet", lambda p: pq.write_table(table, p))


def _arrow_column(values: list, feature: dict):
    import pyarrow as pa

    dtype, shape = feature["dtype"], list(feature["shape"])
    if dtype == "string":
        return pa.array([str(v) for v in values], pa.string())
    if shape == [1]:
        flat = np.asarray(values).reshape(-1).astype(dtype)
        return pa.array(flat)
    flat = np.asarray(values, dtype=dtype).reshape(len(values), -1)
    return pa.FixedSizeListArray.from_arrays(pa.array(flat.reshape(-1)), flat.shape[1])


def _stats(values: list, feature: dict) -> dict | None:
    """lerobot's per-feature statistics: min, max, mean, std, count and quantiles (lists per dimension)."""
    if feature["dtype"] in ("string", "video", "image") or not values:
        return None
    data = np.asarray(values, dtype=np.float64).reshape(len(values), -1)
    out = {"min": data.min(0), "max": data.max(0), "mean": data.mean(0), "std": data.std(0)}
    for q in QUANTILES:
        out[f"q{round(q * 100):02d}"] = np.quantile(data, q, axis=0)
    out = {k: v.tolist() for k, v in out.items()}
    out["count"] = [len(values)]
    return out


def _video_stats(parts: list[np.ndarray]) -> dict | None:
    """Image statistics (per channel, shape (3, 1, 1), values in [0, 1]) from pixel samples."""
    parts = [p for p in parts if len(p)]
    if not parts:
        return None
    pixels = np.concatenate(parts).astype(np.float64) / 255.0  # (n, 3)

    def channels(v: np.ndarray) -> list:
        return v.reshape(3, 1, 1).tolist()

    out = {"min": channels(pixels.min(0)), "max": channels(pixels.max(0)), "mean": channels(pixels.mean(0)),
           "std": channels(pixels.std(0))}
    for q in QUANTILES:
        out[f"q{round(q * 100):02d}"] = channels(np.quantile(pixels, q, axis=0))
    out["count"] = [len(pixels)]
    return out


def _write_json(path: Path, data: dict) -> None:
    _atomic(path, lambda p: p.write_text(json.dumps(data, indent=4) + "\n"))


def _atomic(path: Path, write, suffix: str = ".tmp") -> None:
    """``write(tmp)`` then rename ``tmp`` over ``path``: a reader (or a resumed writer) never sees half a file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.writing{suffix}")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
