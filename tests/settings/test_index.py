import pytest

from traj2events.config import ConfigError, resolve_config
from traj2events.settings.index import index_settings, split_at, split_of


def test_each_trajectory_draws_its_split_and_the_shares_come_out():
    settings = index_settings(resolve_config({}))  # 0.70, 0.15, 0.15
    splits = [split_of(settings, "descent", i) for i in range(4000)]
    for name, share in (("train", 0.70), ("validation", 0.15), ("test", 0.15)):
        assert splits.count(name) / 4000 == pytest.approx(share, abs=0.025)  # ~3.5 sigma of a binomial
    assert splits[:50] == [split_of(settings, "descent", i) for i in range(50)]  # seeded, by id alone
    assert splits != [split_of(settings, "braking", i) for i in range(4000)]  # each scenario its own
    other = {**settings, "seed": settings["seed"] + 1}
    assert splits != [split_of(other, "descent", i) for i in range(4000)]
    everything = {**settings, "splits": {"train": 1.0, "validation": 0.0, "test": 0.0}}
    assert {split_of(everything, "descent", i) for i in range(200)} == {"train"}


def test_shares_that_do_not_add_up_to_one_are_refused_naming_the_key():
    with pytest.raises(ConfigError, match=r"config key 'splits.train': the three shares must add up to 1"):
        resolve_config({"splits": {"train": 0.8, "validation": 0.15, "test": 0.15}})


def test_a_share_of_zero_gets_no_landing_where_the_shares_add_up_to_1_within_1e_9():
    """Read for issue 71: the check accepts shares adding up to 1 - 5e-10, and a draw above
    that went to the test split even with a test share of 0."""
    shares = {"train": 0.5, "validation": 0.5 - 5e-10, "test": 0.0}
    largest = 1.0 - 2**-53  # random()'s largest
    assert split_at(largest, shares) == "validation" and split_at(0.0, shares) == "train"
    assert split_at(largest, {"train": 1.0 - 5e-10, "validation": 0.0, "test": 0.0}) == "train"
    assert split_at(0.5 - 1e-12, shares) == "train" and split_at(0.5 + 1e-9, shares) == "validation"
