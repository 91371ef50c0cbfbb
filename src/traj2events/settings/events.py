"""The event emulation (`events`), declared: the pixel model, the sensor behind its lens,
the readout, the space environment; and the settings of the emulation (the seed aside, per
trajectory) and of its picture."""

from __future__ import annotations

from dataclasses import asdict

from . import pick
from .declare import section, setting

IMX636 = "Sony IMX636 / Prophesee Gen4.1: photodiode area 4.86 x 4.86 um (Prophesee's QE note)"
REFRACTORY_MODES = ("drop", "defer")
READOUT_MODES = ("delay", "drop")
# events.exports: each format's file suffix beside events.h5 (events.npz, events.raw,
# events.aedat4, events.mp4).
EXPORT_SUFFIX = {"npz": "npz", "evt3": "raw", "aedat4": "aedat4", "video": "mp4"}
EXPORT_FORMATS = tuple(EXPORT_SUFFIX)


@section("events.pixel", "the pixel model (docs/events.md): the preset's values, the config's own keys on top")
class EmulatorParams:
    # In events.h5's attribute order (emulator_*): reordering changes the files' bytes.
    theta_on: float = setting(unit="ln", doc="ON contrast threshold", ge=0.01)
    theta_off: float = setting(unit="ln", doc="OFF contrast threshold", ge=0.01)
    sigma: float = setting(unit="ln", doc="per-pixel threshold mismatch (standard deviation)", ge=0)
    cutoff_hz: float = setting(unit="Hz", doc="photoreceptor bandwidth at full scale (255 DN); 0: no low-pass", ge=0)
    refractory_s: float = setting(unit="s", doc="refractory period (0: none)", ge=0)
    leak_hz: float = setting(unit="Hz", doc="leak events' rate", ge=0)
    shot_noise_hz: float = setting(unit="Hz", doc="shot-noise events' rate at full scale", ge=0)
    hot_pixel_fraction: float = setting(doc="fraction of pixels that fire at hot_pixel_hz whatever the input", ge=0,
                                        le=1)  # fmt: skip
    hot_pixel_hz: float = setting(unit="Hz", doc="the hot pixels' rate", ge=0)
    refractory_mode: str = setting(doc="crossings within the period: dropped (drop, ESIM) or pending (defer, v2e)",
                                   choices=REFRACTORY_MODES)  # fmt: skip

    def __post_init__(self) -> None:
        if self.hot_pixel_fraction > 0 and not self.hot_pixel_hz > 0:
            raise ValueError("events.pixel.hot_pixel_hz: expected > 0 when events.pixel.hot_pixel_fraction > 0")


@section(
    "events.sensor",
    'the event camera behind its lens: radiance -> photocurrent, for input: sensor (docs/events.md "Sensor model")',
)
class SensorParams:
    f_number: float = setting(2.0, "", "the lens's f-number N (image irradiance pi tau L / 4 N^2): a fast "
                              "machine-vision lens; from f/0.5, a lens's limit in air (N = 1 / 2 NA, NA <= 1), to "
                              "f/1000, a pinhole's", source="assumed", ge=0.5, le=1000)  # fmt: skip
    optics_transmittance: float = setting(0.9, "", "the lens's transmittance tau: a coated multi-element lens "
                                          "(from 1e-3: a dense neutral filter)", source="assumed", ge=1e-3,
                                          le=1)  # fmt: skip
    pixel_pitch_m: float = setting(4.86e-6, "m", "pixel pitch: 0.5 um (below a visible wavelength) to 100 um (event "
                                   "pixels: 4-40 um)", source=IMX636, ge=5.0e-7, le=1.0e-4)  # fmt: skip
    quantum_efficiency: float = setting(
        0.5,
        "",
        "electrons per photon over the whole pixel area: a back-illuminated sensor in the visible (from 1e-3)",
        source="assumed",
        ge=1e-3,
        le=1,
    )
    band_m: tuple[float, float] = setting((4.0e-7, 7.0e-7), "m", "[low, high] wavelengths of the sensor's band: the "
                                          "visible behind an IR-cut filter, within silicon's 0.2-1.2 um",
                                          ge=2.0e-7, le=1.2e-6)  # fmt: skip
    dark_current_a: float = setting(1.0e-15, "A", "dark current per pixel, the knee of the log response: the order "
                                    "of IMX636's 0.08 lx low-light cutoff (0.6 fA at 555 nm, QE 0.5); above 100 pA "
                                    "sunlit regolith would drown; from 1e-21 A, a cooled CCD's 0.006 e-/s",
                                    ge=1.0e-21, le=1.0e-10)  # fmt: skip
    psf_diffraction: bool = setting(False, "", "blur the radiance by the lens's Airy pattern (f_number over band_m) "
                                    "before the log (docs/events.md \"Optics\")")  # fmt: skip
    lens_blur_um: float = setting(0.0, "um", "and by a Gaussian lens blur of this standard deviation at the focal "
                                  "plane (0: none)", ge=0, le=100)  # fmt: skip
    vignetting: bool = setting(False, "", "cos^4 fall-off of the image irradiance with the field angle; all three "
                               "off: the paper's pinhole")  # fmt: skip

    def __post_init__(self) -> None:
        object.__setattr__(self, "band_m", tuple(self.band_m))
        if not self.band_m[0] < self.band_m[1]:
            raise ValueError(f"events.sensor.band_m: expected [low, high] with low < high, got {list(self.band_m)}")

    @property
    def has_optics(self) -> bool:
        return self.psf_diffraction or self.lens_blur_um > 0 or self.vignetting

    @classmethod
    def from_config(cls, sensor: dict) -> SensorParams:
        from .declare import declared_fields

        known = {f.name for f in declared_fields(cls)}
        unknown = sorted(set(sensor) - known)
        if unknown:
            raise ValueError(f"events.sensor: unknown keys {unknown}; expected {sorted(known)}")
        return cls(**sensor)

    def to_config(self) -> dict:
        return {**asdict(self), "band_m": list(self.band_m)}


@section(
    "events.readout",
    'from the pixels to the output (docs/events.md "Readout"); all off: events leave '
    "when their pixels cross, as in the paper",
)
class ReadoutParams:
    latency_s: float = setting(0.0, "s", "mean delay of an event after its crossing (IEBCS's model: normal, clipped "
                               "at 0)", ge=0, le=1)  # fmt: skip
    jitter_s: float = setting(0.0, "s", "the delay's standard deviation", ge=0, le=1)
    max_event_rate_hz: float = setting(0.0, "Hz", "the readout's limit, events/s (0: none)", ge=0)
    mode: str = setting("delay", "", "past the limit: delay (an arbiter's queue: late, none lost) or drop (an "
                        "event-rate controller: at most the limit in any 1 ms)", choices=READOUT_MODES)  # fmt: skip

    @property
    def active(self) -> bool:
        return self.latency_s > 0 or self.jitter_s > 0 or self.max_event_rate_hz > 0


@section(
    "events.space",
    "the space environment's own events, for input: sensor; off: none, as the paper and a "
    'camera on the ground (docs/events.md "Space environment")',
)
class SpaceParams:
    enabled: bool = setting(False, "", "add particle hits and row or column glitches")
    particle_flux_cm2_s: float = setting(
        2.0,
        "cm^-2 s^-1",
        "charged particles crossing the sensor: galactic cosmic "
        "rays, of the order of 4 per cm^2 per s beyond the Earth's magnetosphere, "
        "about half near the Moon, which hides half the sky",
        ge=0,
        le=1.0e7,
    )
    sensitive_depth_um: float = setting(5.0, "um", "the depth a photodiode collects charge from", source="assumed",
                                        gt=0, le=100)  # fmt: skip
    charge_diffusion_um: float = setting(1.0, "um", "the charge cloud's spread (standard deviation)",
                                         source="assumed", gt=0, le=100)  # fmt: skip
    row_column_hz: float = setting(0.0, "Hz", "whole-row or whole-column glitches per second (seen on Falcon Neuro; "
                                   "rate not published)", ge=0, le=1.0e4)  # fmt: skip
    glitch_duration_s: float = setting(1.0e-4, "s", "a glitch's events fall within this time", source="assumed",
                                       ge=0, le=1)  # fmt: skip


@section("events", "event emulation from the rendered linear radiance (docs/events.md)")
class EventsSection:
    preset: str = setting("paper", "", "the pixel model's values: a file of src/traj2events/presets/ (paper: the "
                          "paper's Table 2; clean: no noise, no low-pass, no mismatch; imx636, davis346: sensors "
                          "that exist, which also set events.sensor and events.readout keys)")  # fmt: skip
    pixel: EmulatorParams = setting({}, "", "keys that change the preset's values, e.g. {refractory_s: 0.001}")
    window_ms: float = setting(10.0, "ms", "event frames' window: the paper's 10 ms; from 1 us, the events' clock "
                               "(shorter ones rounded to 0 us: frames with no events)", ge=0.001)  # fmt: skip
    input: str = setting("sensor", "", "frames.h5's radiance into the emulator: sensor (the photocurrent, "
                         "events.sensor) or display (255 L / render.display_white_w_m2_sr, the videos' scale)",
                         choices=("sensor", "display"))  # fmt: skip
    sensor: SensorParams = setting(SensorParams, "", "the sensor")
    readout: ReadoutParams = setting(ReadoutParams, "", "the readout")
    space: SpaceParams = setting(SpaceParams, "", "the space environment")
    labels: bool = setting(True, "", "write events/label in events.h5: each event's cause (signal, shot noise, "
                           "leak, hot pixel, radiation, glitch)")  # fmt: skip
    device: str = setting("cpu", "", "where the pixel model runs: cpu, or cuda (an NVIDIA GPU, pip install "
                          ".[gpu]): the same events but where the GPU rounds a crossing time differently",
                          choices=("cpu", "cuda"))  # fmt: skip
    exports: list[str] = setting([], "", "copies of events.h5 in other formats, on request, each its own job "
                                 "(added to a built dataset without emulating again): npz (ELOPE), evt3 (Prophesee "
                                 "EVT 3.0 .raw), aedat4, video (events.mp4: ON light, OFF dark on grey, a frame "
                                 "per pose)", choices=EXPORT_FORMATS,
                                 schema={"uniqueItems": True})  # fmt: skip


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
# The events command's options where a key's own name would say too little.
EVENTS_FLAGS = {"events.input": "--input-scale", "events.readout.mode": "--readout-mode",
                "events.space.enabled": "--space"}  # fmt: skip


def events_settings(config: dict) -> dict:
    """Everything the emulation depends on (the seed aside, per trajectory): the pixel
    model (and the preset it came from), labels, the input scale, the sensor and its readout,
    and the device it runs on (a GPU can round a crossing differently); events.h5's
    compression."""
    return pick(config, EVENTS)


def events_picture_settings(config: dict) -> dict:
    """The event-frame picture's window."""
    return pick(config, EVENTS_PICTURE)
