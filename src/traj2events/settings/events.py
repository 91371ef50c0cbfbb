"""Settings of the event emulation (the seed aside, per trajectory) and of its picture."""

from __future__ import annotations

from . import pick

# events.pixel: the preset's values under the config's own keys (defaults.with_preset).
EVENTS = {
    "preset": "events.preset",
    "pixel": "events.pixel",
    "labels": "events.labels",
    "input": "events.input",
    "sensor": "events.sensor",
}
EVENTS_PICTURE = {"window_ms": "events.window_ms"}


def events_settings(config: dict) -> dict:
    """Everything the emulation depends on (the seed aside, per trajectory): the pixel
    model (and the preset it came from), labels, the input scale and the sensor."""
    return pick(config, EVENTS)


def events_picture_settings(config: dict) -> dict:
    """The event-frame picture's window."""
    return pick(config, EVENTS_PICTURE)
