"""Settings of the event emulation (the seed aside, per trajectory)."""

from __future__ import annotations

EVENTS_KEYS = ("preset", "refractory_s", "refractory_mode", "hot_pixel_fraction", "hot_pixel_hz", "labels", "input")


def events_settings(config: dict) -> dict:
    """Everything the emulation depends on (the seed aside, per trajectory): the pixel
    model's preset and the keys that override it, labels, the input scale and the sensor."""
    events = config["events"]
    return {**{key: events[key] for key in EVENTS_KEYS}, "sensor": dict(events["sensor"])}
