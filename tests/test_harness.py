"""The trial's protocols and the disturbance setting every front end builds."""

import math

import pytest

from agentchord.harness import KINDS, PRESETS, UNDISTURBED, DisturbanceSetting, parse_kinds
from agentchord.sim.disturbances import ProtocolDisturbances, RandomDisturbances, schedule


def test_options_become_one_setting_the_same_way():
    real = DisturbanceSetting.from_options(p=0.3, disturb="drop", protocol="real")
    assert (real.kinds, real.protocol) == (PRESETS["real"], "real")  # a preset brings its own kinds
    custom = DisturbanceSetting.from_options(disturb="shift,knock", protocol="custom")
    assert custom.kinds == ("shift", "knock") == DisturbanceSetting.from_options(disturb=("shift", "knock"), protocol="custom").kinds
    drops = DisturbanceSetting.from_options(p=0.1)
    assert (drops.p, drops.kinds, drops.protocol) == (0.1, ("drop",), None)
    assert UNDISTURBED == DisturbanceSetting() and not UNDISTURBED.disturbed and drops.disturbed and custom.disturbed


@pytest.mark.parametrize("options,words", [
    ({"p": 1.5}, "finite number in [0, 1]"),
    ({"p": math.nan}, "finite number in [0, 1]"),
    ({"disturb": "teleport"}, "unknown disturbance kind"),
    ({"disturb": ""}, "unknown disturbance kind"),
    ({"protocol": "lab"}, "unknown disturbance protocol"),
    ({"protocol": "custom", "window": (50, 50)}, "window"),
])
def test_a_bad_setting_is_refused_with_what_is_wrong(options, words):
    with pytest.raises(ValueError, match=words.replace("[", r"\[").replace("]", r"\]")):
        DisturbanceSetting.from_options(**options)


def test_a_setting_says_what_it_is_and_draws_its_schedule_from_the_seed():
    real = DisturbanceSetting.from_options(protocol="real", window=(10, 20))
    assert real.to_dict() == {"p": 0.0, "kinds": ["perturb", "pull"], "protocol": "real"}
    assert real.describe() == "perturb, pull: 1-2 per trial (real protocol)"
    assert DisturbanceSetting(p=0.1).describe() == "drop at p = 0.1 per action" and UNDISTURBED.describe() == "none"
    drawn = schedule(real, 7)
    assert isinstance(drawn, ProtocolDisturbances) and (drawn.seed, drawn.kinds, drawn.window) == (7, real.kinds, (10, 20))
    assert isinstance(schedule(DisturbanceSetting(p=0.2, kinds=KINDS), 3), RandomDisturbances)
    assert schedule(UNDISTURBED, 3) is None
    assert parse_kinds(" drop , pull ") == ("drop", "pull")
