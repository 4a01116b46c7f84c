"""Local worker pools: the same results in any number of processes, as they finish."""

import pytest

from agentchord.bench.runner import default_workers, pooled


@pytest.mark.parametrize("workers", [1, 2])
def test_a_pool_gives_every_result_once_whatever_the_workers(workers):
    items = [-3, -1, 2, -7]
    assert sorted(pooled(abs, items, workers)) == [1, 2, 3, 7]


def test_no_items_and_the_default_worker_count():
    assert list(pooled(abs, [], None)) == []
    assert default_workers() >= 1
