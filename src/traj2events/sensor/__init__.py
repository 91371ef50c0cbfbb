"""The event camera: optics and pixel as a sensor records the scene (docs/events.md).

Read first (the model):
    photocurrent   rendered radiance -> the photocurrent of a pixel behind its lens
    laws           the pixel's laws, each written once: lin-log response, bandwidth and
                   low-pass gain, shot-noise gain, refractory period
    emulator       the streaming emulator: per-pixel state, the eight steps of the model
    pixel          the per-pixel loop over one frame interval (crossings, their times)

Machinery a reader may skip:
    noise          shot noise drawn by thinning from an alias table, prefetched
    ordering       each interval's events sorted by (t, y, x, p) with packed keys
    parallel       the per-pixel pass split over threads
"""
