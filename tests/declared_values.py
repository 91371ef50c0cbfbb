"""Hypothesis strategies for a settings section's every key, drawn across the bounds its
declarations give (settings.declare): the property tests that drive a stage with configs
the check accepts (docs/accuracy.md "End-to-end stress")."""

import numpy as np
from hypothesis import strategies as st

from normal_floats import normal_floats
from traj2events.settings.declare import declared_fields

# Caps on the bounds the declarations leave open (a rate's ge=0 and no more), by unit: for
# the events stage, events enough to exercise every law in a 3 x 4 image over 0.4 s, few
# enough to stay a unit test.
OPEN_CAPS = {"Hz": 1e4, "s": 0.05, "ln": 5.0, "cm^-2 s^-1": 1e5, "": 1.0}


def declared_values(cls, normal: bool = False, **caps):
    """A strategy for a section's every key, drawn across its declared bounds (open ones
    capped by unit, OPEN_CAPS, or by `caps`): floats (subnormals included, as the config
    check accepts them; `normal`: 0 or >= 1e-100, for a law's relative bound), choices,
    booleans."""
    keys = {}
    for f in declared_fields(cls):
        meta, bounds = f.metadata, f.metadata["bounds"]
        if meta["choices"]:
            keys[f.name] = st.sampled_from(meta["choices"])
        elif f.type in ("bool", bool):
            keys[f.name] = st.booleans()
        elif f.type in ("float", float):
            lo = bounds.get("ge", bounds.get("gt", 0.0))
            hi = bounds.get("le", bounds.get("lt"))
            hi = min(hi if hi is not None else np.inf, caps.get(f.name, OPEN_CAPS.get(meta["unit"], np.inf)))
            floats = normal_floats(lo, hi) if normal else st.floats(lo, hi)
            keys[f.name] = floats.filter(lambda x, b=bounds: x > b.get("gt", -np.inf))
    return st.fixed_dictionaries(keys)
