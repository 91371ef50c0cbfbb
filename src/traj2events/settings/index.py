"""The dataset index's settings (`splits`): which landings are for training, validation and
testing. A trajectory's split is drawn from the dataset's seed, its scenario and its id
alone, as its Sun is (`split_of`): the same config gives the same splits, and adding
trajectories leaves the others' where they were."""

from __future__ import annotations

import math

from . import pick, trajectory_rng
from .declare import section, setting

SPLIT_NAMES = ("train", "validation", "test")


@section("splits", "the landings' train, validation and test shares, drawn per trajectory (docs/dataset.md "
         '"index.csv")')  # fmt: skip
class SplitsSection:
    train: float = setting(0.7, "", "the share of landings to train on", ge=0, le=1)
    validation: float = setting(0.15, "", "the share to validate on", ge=0, le=1)
    test: float = setting(0.15, "", "the share to test on", ge=0, le=1)

    def __post_init__(self) -> None:
        if not math.isclose(self.train + self.validation + self.test, 1.0, abs_tol=1e-9):
            raise ValueError(f"splits.train: the three shares must add up to 1, got {self.train} + "
                             f"{self.validation} + {self.test}")  # fmt: skip


INDEX = {"seed": "seed", "splits": "splits"}


def index_settings(config: dict) -> dict:
    """What the index depends on beyond its files: the seed and the split shares."""
    return pick(config, INDEX)


def split_of(settings: dict, scenario: str, trajectory_id: int) -> str:
    """The split of one trajectory, from a uniform draw u in [0, 1) of its own (split_at)."""
    return split_at(trajectory_rng(settings, scenario, f"{trajectory_id:04d}", "split").random(), settings["splits"])


def split_at(u: float, shares: dict) -> str:
    """train below the train share of u's [0, 1), validation below train + validation, else
    test; the shares scaled by their sum (within 1e-9 of 1), so that a share of 0 gets no
    landing."""
    u *= shares["train"] + shares["validation"] + shares["test"]
    if u < shares["train"]:
        return "train"
    return "validation" if u < shares["train"] + shares["validation"] else "test"
