"""Are two sweeps the same episodes? A diff of records.jsonl without the clock.

    python benchmarks/compare_records.py OUT_BEFORE/records.jsonl OUT_AFTER/records.jsonl

Prints how many episodes both hold and, per method, which fields differ (wall time and measured
compute left out: they differ between two runs of the same code). Exit 0 when identical, 1 when
not, 2 for a file that cannot be read.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from agentchord.bench.compare import compare_records, comparison_markdown


def read_records(path: Path) -> list[dict]:
    """The records of a sweep's ``records.jsonl``, one per line.

    Raises:
        ValueError: A line that is not a JSON object with an ``id`` (named by file and line).
    """
    records = []
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if not line.strip():
            continue
        try:
            record = json.loads(line)
        except json.JSONDecodeError as exc:
            raise ValueError(f"{path}:{number}: not a JSON record ({exc.msg})") from None
        if not isinstance(record, dict) or "id" not in record:
            raise ValueError(f"{path}:{number}: a record is a JSON object with an id")
        records.append(record)
    return records


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    try:
        before, after = (read_records(Path(p)) for p in argv)
    except (OSError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    comparison = compare_records(before, after)
    print(comparison_markdown(comparison), end="")
    return 0 if comparison.identical else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
