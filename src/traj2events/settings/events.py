"""Settings of the event emulation (the seed aside, per trajectory) and of its picture."""

from __future__ import annotations

from . import pick, without_late_defaults

# events.pixel: the preset's values under the config's own keys (defaults.with_preset).
EVENTS = {
    "preset": "events.preset",
    "pixel": "events.pixel",
    "labels": "events.labels",
    "input": "events.input",
    "sensor": "events.sensor",
    "readout": "events.readout",
    "space": "events.space",
    "device": "events.device",
    "compression": "compression",  # events.h5's
}
EVENTS_PICTURE = {"window_ms": "events.window_ms"}
# events.exports: each format's file suffix beside events.h5 (events.npz, events.raw, events.aedat4).
EXPORT_SUFFIX = {"npz": "npz", "evt3": "raw", "aedat4": "aedat4"}
# The events command's options where a key's own name would say too little.
EVENTS_FLAGS = {"events.input": "--input-scale", "events.readout.mode": "--readout-mode",
                "events.space.enabled": "--space"}  # fmt: skip


def events_settings(config: dict) -> dict:
    """Everything the emulation depends on (the seed aside, per trajectory): the pixel
    model (and the preset it came from), labels, the input scale, the sensor and its readout,
    and the device it runs on (a GPU can round a crossing differently); events.h5's
    compression where it is not the default."""
    return without_late_defaults(pick(config, EVENTS))


def events_picture_settings(config: dict) -> dict:
    """The event-frame picture's window."""
    return pick(config, EVENTS_PICTURE)
