"""The sampling loop: failed draws are replaced until the scenario has its trajectories,
within max_draws, in an order that does not depend on the workers."""

from types import SimpleNamespace

import numpy as np
import pytest

from traj2events.stages.sample_trajectories import NOT_IN_DATASET, dataset_ids
from traj2events.trajectory import batch


def fake_result(index: int, failing: set[int]):
    return SimpleNamespace(index=index, success=index not in failing)


@pytest.mark.parametrize(
    "n, failing, expected_draws",
    [
        (3, set(), 3),  # nothing fails: exactly n draws
        (3, {1}, 4),  # one failure, one replacement
        (3, {1, 3}, 5),  # the replacement fails too: another round
        (2, {0, 1, 2, 3, 4, 5}, 6),  # never enough: stops at max_draws(2) = 6
    ],
)
def test_failed_draws_are_replaced_within_max_draws(monkeypatch, n, failing, expected_draws):
    monkeypatch.setattr(batch, "_init_worker", lambda *args: None)
    monkeypatch.setattr(batch, "_solve_one", lambda index: fake_result(index, failing))
    scenario = SimpleNamespace(n_trajectories=n)
    results = batch.solve_samples(None, None, scenario, 0, None, None, jobs=1)
    assert [r.index for r in results] == list(range(expected_draws))
    assert expected_draws <= batch.max_draws(n)
    solved = sum(r.success for r in results)
    assert solved == min(n, expected_draws - len(failing & set(range(expected_draws))))
    ids = dataset_ids(results)
    assert [i for i in ids if i != NOT_IN_DATASET] == list(range(solved))  # solved draws numbered in draw order
    assert all((i == NOT_IN_DATASET) == (not r.success) for i, r in zip(ids, results))


def test_max_draws_gives_at_least_four_replacements():
    assert [batch.max_draws(n) for n in (1, 4, 10, 167)] == [5, 8, 20, 334]
    assert np.all(np.diff([batch.max_draws(n) for n in range(1, 50)]) >= 1)
