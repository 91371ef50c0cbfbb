"""The event camera: optics and pixel as a sensor records the scene (docs/events.md).

Read first (the model):
    photocurrent   rendered radiance -> the photocurrent of a pixel behind its lens
    laws           the pixel's laws, each written once: lin-log response, bandwidth and
                   low-pass gain, shot-noise gain, refractory period
    emulator       the streaming emulator: per-pixel state, the eight steps of the model
    pixel          the model of one pixel over one frame interval (crossings, their times),
                   and its two passes over a frame on the CPU
    noise          shot noise (thinning per block of pixels) and hot pixels
    optics         the lens before the log: point-spread function, vignetting
    readout        after the pixels: latency, jitter, the readout's rate limit
    radiation      the space environment's events: particle hits, row and column glitches

Machinery a reader may skip:
    sources        the frames it takes: frames.h5, a render job's frames, a video, images
    frame_transforms  what a user does to them first: retime, time window, crop, resize
    draws          random draws keyed by (seed, interval, pixel, draw): counter-based hashing
    cuda_kernels   the same model on an NVIDIA GPU, one thread per pixel
    ordering       each interval's events sorted by (t, y, x, p) with packed keys
    parallel       the per-pixel pass split over threads
"""
