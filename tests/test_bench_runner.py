"""Local worker pools: the same results in any number of processes, as they finish."""

import pytest

from agentchord.bench.runner import pooled


@pytest.mark.parametrize("workers", [1, 2])
def test_a_pool_gives_every_result_once_whatever_the_workers(workers):
    items = [-3, -1, 2, -7]
    assert sorted(pooled(abs, items, workers)) == [1, 2, 3, 7]


def test_no_items_give_no_results():
    assert list(pooled(abs, [], None)) == []
