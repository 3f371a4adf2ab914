"""core.cpus: the one bound every --workers option shares (issue 29: --workers 1000000 started 42 processes)."""

from __future__ import annotations

import pytest

from cellstress.core.cpus import MAX_WORKERS_PER_CORE, check_workers, max_workers, usable_cpus
from cellstress.core.errors import CellstressError


def test_the_bound_is_per_usable_core():
    assert usable_cpus() >= 1 and max_workers() == MAX_WORKERS_PER_CORE * usable_cpus()


@pytest.mark.parametrize("value", [None, 1, max_workers()])
def test_within_the_bound(value):
    assert check_workers(value) == value


@pytest.mark.parametrize("value", [0, -1, max_workers() + 1, 10**6, True, 2.0, "2"])
def test_outside_the_bound(value):
    with pytest.raises(CellstressError, match=rf"--workers must be a whole number in 1\.\.{max_workers()} "):
        check_workers(value)
