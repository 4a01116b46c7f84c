"""Episode records on disk: JSON lines appended as each episode finishes, resumable after a kill.

A sweep's directory holds ``sweep.json`` (the configuration its records depend on) and
``records.jsonl`` (one record per line). A record is appended with one ``write`` and an
``fsync`` before the next episode is counted, so a kill -9 loses at most the line being
written; reopening drops that torn tail. Rerunning the sweep skips every key already there,
except an episode that stopped on an internal error: it runs again, and its new record,
appended later, is the one that counts.

One sweep at a time per directory: a store holds a lock on ``.sweep.lock`` (a POSIX record lock,
released when its process ends, however it ends); a second sweep on the same ``--out`` is
refused, naming the process that holds it.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from agentchord.bench.exceptions import SweepStoreError
from agentchord.bench.record import check_record
from agentchord.bench.sweep import RECORD_VERSION, SweepConfig, is_error
from agentchord.guard.exceptions import OutputPathError
from agentchord.guard.locks import lock_folder
from agentchord.guard.outputs import atomic_write_text, finite_json

MANIFEST = "sweep.json"
RECORDS = "records.jsonl"
LOCK = ".sweep.lock"


class RecordStore:
    """The records of one sweep directory.

    Args:
        directory: The sweep's directory (created if missing).
        config: The sweep's configuration; an existing directory must hold the same.

    Raises:
        SweepStoreError: The directory is a file or cannot be written, holds a sweep with
            another configuration, or a record in it is not valid (the file and line are named).
    """

    def __init__(self, directory: str | Path, config: SweepConfig) -> None:
        self.directory = Path(directory)
        if self.directory.exists() and not self.directory.is_dir():
            raise SweepStoreError(f"{self.directory}: not a directory")
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise SweepStoreError(f"{self.directory}: cannot create the directory ({error.strerror})") from None
        self.path = self.directory / RECORDS
        self._lock: int | None = self._acquire_lock()
        self._check_manifest(config)
        self.records: dict[str, dict] = {}
        self._load()

    def _acquire_lock(self) -> int:
        """Lock the directory for this process; refuse if another process holds it."""
        try:
            return lock_folder(self.directory, LOCK, "sweep")
        except OutputPathError as error:
            raise SweepStoreError(f"{error.path}: {error.reason}") from None

    def close(self) -> None:
        """Release the directory's lock (it is released anyway when the process ends)."""
        if self._lock is not None:
            os.close(self._lock)
            self._lock = None

    def _check_manifest(self, config: SweepConfig) -> None:
        manifest = self.directory / MANIFEST
        wanted = config.to_dict()
        if manifest.exists():
            try:
                found = json.loads(manifest.read_text())
            except (OSError, ValueError) as error:
                raise SweepStoreError(f"{manifest}: not a sweep manifest ({error})") from None
            if isinstance(found, dict):
                found.setdefault("reasoner", "rules")  # sweeps written before --reasoner were rules sweeps
            if found != wanted:
                changed = sorted(k for k in set(found) | set(wanted) if found.get(k) != wanted.get(k))
                raise SweepStoreError(
                    f"{manifest}: this directory holds a sweep with another configuration ({', '.join(changed)} differ); "
                    "use another --out, or the same options as that sweep"
                )
            return
        try:
            atomic_write_text(manifest, finite_json(wanted, indent=2) + "\n")
        except OSError as error:
            raise SweepStoreError(f"{manifest}: cannot write ({error.strerror})") from None

    def _load(self) -> None:
        if not self.path.exists():
            return
        if not self.path.is_file():
            raise SweepStoreError(f"{self.path}: not a records file (a directory or a device); move it away or use another --out")
        try:
            data = self.path.read_bytes()
            end = data.rfind(b"\n") + 1
            if end < len(data):
                # A torn last line (killed mid-write): that episode runs again.
                with open(self.path, "r+b") as handle:
                    handle.truncate(end)
                    handle.flush()
                    os.fsync(handle.fileno())
        except OSError as error:
            raise SweepStoreError(f"{self.path}: cannot read and resume it ({error.strerror})") from None
        for number, line in enumerate(data[:end].splitlines(), start=1):
            if not line.strip():
                continue
            try:
                record = json.loads(line)
            except ValueError as error:
                raise SweepStoreError(f"{self.path}: line {number}: not a JSON record ({error})") from None
            if isinstance(record, dict) and record.get("version") != RECORD_VERSION:
                raise SweepStoreError(f"{self.path}: line {number}: record version {record.get('version')!r}, expected {RECORD_VERSION}")
            problems = check_record(record)
            if problems:
                raise SweepStoreError(f"{self.path}: line {number}: " + "; ".join(problems))
            if not (is_error(record) and record["id"] in self):  # a verdict is never replaced by an error
                self.records[record["id"]] = record

    def __contains__(self, key_id: str) -> bool:
        """Whether the episode has run to a verdict (an internal error's record does not count)."""
        record = self.records.get(key_id)
        return record is not None and not is_error(record)

    def __len__(self) -> int:
        return len(self.records)

    def append(self, record: dict) -> None:
        """Write one record durably (one write, then fsync); a finished key is not written twice."""
        if record["id"] in self:
            return
        line = (finite_json(record, separators=(",", ":")) + "\n").encode()
        with open(self.path, "ab") as handle:
            handle.write(line)
            handle.flush()
            os.fsync(handle.fileno())
        self.records[record["id"]] = record
