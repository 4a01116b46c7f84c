"""What can go wrong in a benchmark sweep."""

from __future__ import annotations


class BenchError(Exception):
    """Base of the benchmark's errors."""


class SweepStoreError(BenchError):
    """A sweep directory that cannot be used: another sweep's, unwritable, or a bad record in it."""


class BackendError(BenchError):
    """A backend that cannot run: Ray not installed, or its cluster not reachable."""
