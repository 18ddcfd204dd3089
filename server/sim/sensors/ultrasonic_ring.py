"""The TurtleBot's ring of seven HC-SR04 ultrasonic rangers, fired one after another.

Source: 003_4f92d1fa0a49ddae.txt section 3.4 (seven HC-SR04 on the third tower layer, 4 m range,
15 degree detection angle, activated one after another following the sequence of its Figure 3.4
so their echoes do not interfere) and section 5.6 (one topic per sensor).

- Message: sensor_msgs/Range, radiation_type ULTRASOUND, one topic per ranger
  (`ultrasonic/range_0` .. `ultrasonic/range_6`, frames `ultrasonic_0` .. `ultrasonic_6`),
  numbered from the rightmost ranger (index 0) to the leftmost (index 6).
- Units and range: metres, 0.02-4 m; field_of_view 15 degrees (in radians).
- Placement (ASSUMPTION: the paper's Figure 3.4 is missing from our copy): across the front half,
  bearings -90, -60, -30, 0, +30, +60, +90 degrees (robot frame, 0 ahead, + left), on a circle of
  0.15 m radius around the body centre.
- Firing (ASSUMPTION for the figure's order): sequence 0, 3, 6, 2, 5, 1, 4, one ping every 60 ms
  (the HC-SR04 needs ~60 ms for its echo to die out). Consecutive pings, including the last of
  one cycle and the first of the next, are never neighbours. Every ranger has the same rate,
  1 / (7 x 60 ms) = 2.38 Hz, and the phase of its slot in the sequence.
- Echo model: 7 rays across the 15-degree cone; a ray echoes only if it meets a surface within
  60 degrees of head-on (ultrasound reflects specularly off flat surfaces, so a surface at grazing
  incidence sends the ping away). The reading is the nearest echoing ray. No echo at all reads
  max_range (the HC-SR04's echo pulse times out, and the driver reports its full range).
- Noise: Gaussian, sd = 5 mm + 0.2 % of the range; the result is clipped to [0.02, 4] m.
"""

from __future__ import annotations

import math

import numpy as np

from sandbox.msgs.sensor_msgs import Range
from server.sim.sensors.base import SenseContext, StatelessSensor
from server.sim.sensors.frames import stamped_header
from server.sim.sensors.mount import Mount

# Defaults (HC-SR04 datasheet and paper section 3.4 unless noted)
# | name                  | value              | unit  | why                                    |
# |-----------------------|--------------------|-------|----------------------------------------|
_FIELD_OF_VIEW_RAD = math.radians(15.0)  # [rad] detection angle, section 3.4
_MIN_RANGE_M = 0.02  # [m]                     datasheet minimum
_MAX_RANGE_M = 4.0  # [m]                      section 3.4
_PING_INTERVAL_S = 0.06  # [s]                 datasheet: >= 60 ms between triggers
_BEARINGS_RAD = tuple(math.radians(d) for d in (-90, -60, -30, 0, 30, 60, 90))  # assumption
_ACTIVATION_SEQUENCE = (0, 3, 6, 2, 5, 1, 4)  # [-] assumption; no neighbours back to back
_MOUNT_RADIUS_M = 0.15  # [m]                  third tower layer edge (assumption)
_CONE_RAYS = 7  # [-]                          rays sampled across the cone
_MAX_INCIDENCE_RAD = math.radians(60.0)  # [rad] beyond this a flat surface returns no echo
_NOISE_SD_M = 0.005  # [m]                     timing jitter of the echo pulse
_NOISE_FRACTION = 0.002  # [-]                 speed-of-sound error grows with range
_MIN_HEIGHT_M = 0.0  # [m]                     the cone also spreads vertically: low things echo


class RingRanger(StatelessSensor):
    """One HC-SR04 of the ring, publishing sensor_msgs/Range at its own phase (see module doc)."""

    msg_type = Range

    def __init__(
        self,
        *,
        bearing_rad: float,
        rate_hz: float,
        phase_s: float,
        frame_id: str,
        mount_radius_m: float = _MOUNT_RADIUS_M,
        field_of_view_rad: float = _FIELD_OF_VIEW_RAD,
        min_range_m: float = _MIN_RANGE_M,
        max_range_m: float = _MAX_RANGE_M,
        cone_rays: int = _CONE_RAYS,
        max_incidence_rad: float = _MAX_INCIDENCE_RAD,
        noise_sd_m: float = _NOISE_SD_M,
        noise_fraction: float = _NOISE_FRACTION,
        min_height_m: float = _MIN_HEIGHT_M,
    ) -> None:
        if cone_rays < 1:
            raise ValueError(f"RingRanger needs cone_rays >= 1, got {cone_rays}.")
        self.bearing_rad = float(bearing_rad)
        self.rate_hz = float(rate_hz)
        self.phase_s = float(phase_s)
        self.frame_id = frame_id
        self.mount_radius_m = float(mount_radius_m)
        self.field_of_view_rad = float(field_of_view_rad)
        self.min_range_m = float(min_range_m)
        self.max_range_m = float(max_range_m)
        self.max_incidence_rad = float(max_incidence_rad)
        self.noise_sd_m = float(noise_sd_m)
        self.noise_fraction = float(noise_fraction)
        self.min_height_m = float(min_height_m)
        half = 0.5 * self.field_of_view_rad
        self._ray_offsets_rad = (
            np.linspace(-half, half, cone_rays) if cone_rays > 1 else np.zeros(1)
        )
        self.mount = Mount(
            x_m=self.mount_radius_m * math.cos(self.bearing_rad),
            y_m=self.mount_radius_m * math.sin(self.bearing_rad),
            yaw_rad=self.bearing_rad,
        )

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> Range:
        x_m, y_m, heading_rad = self.mount.in_world(ctx.state.pose)
        hits = ctx.obstacles.cast(
            np.array([x_m, y_m]),
            heading_rad + self._ray_offsets_rad,
            self.max_range_m,
            min_height_m=self.min_height_m,
        )
        echoes = np.isfinite(hits.distance_m) & (hits.incidence_rad <= self.max_incidence_rad)
        nearest_m = float(np.min(np.where(echoes, hits.distance_m, self.max_range_m)))
        sd_m = self.noise_sd_m + self.noise_fraction * nearest_m
        noise_m = sd_m * float(rng.standard_normal())
        # No echo is a timeout, not a measurement: it reads max_range exactly.
        measured_m = nearest_m + noise_m if echoes.any() else self.max_range_m
        return Range(
            header=stamped_header(ctx.time_s, self.frame_id),
            radiation_type=Range.ULTRASOUND,
            field_of_view=self.field_of_view_rad,
            min_range=self.min_range_m,
            max_range=self.max_range_m,
            range=min(max(measured_m, self.min_range_m), self.max_range_m),
        )


class UltrasonicRing:
    """Builds the seven `RingRanger`s of the ring with phases that fire them one after another.

    `rangers` lists them in placement order (index 0 = rightmost); `topics` maps each topic name
    to its ranger; `cycle_s` [s] is the time for the whole sequence.
    """

    def __init__(
        self,
        *,
        bearings_rad: tuple[float, ...] = _BEARINGS_RAD,
        activation_sequence: tuple[int, ...] = _ACTIVATION_SEQUENCE,
        ping_interval_s: float = _PING_INTERVAL_S,
        mount_radius_m: float = _MOUNT_RADIUS_M,
        topic_prefix: str = "ultrasonic/range_",
        frame_prefix: str = "ultrasonic_",
        **ranger_options: float,
    ) -> None:
        count = len(bearings_rad)
        _check_sequence(activation_sequence, count)
        if ping_interval_s <= 0.0:
            raise ValueError(f"UltrasonicRing needs ping_interval_s > 0, got {ping_interval_s}.")
        self.bearings_rad = tuple(float(b) for b in bearings_rad)
        self.activation_sequence = tuple(activation_sequence)
        self.ping_interval_s = float(ping_interval_s)
        self.cycle_s = count * self.ping_interval_s
        slot_of = {index: slot for slot, index in enumerate(self.activation_sequence)}
        self.rangers = tuple(
            RingRanger(
                bearing_rad=bearing,
                rate_hz=1.0 / self.cycle_s,
                phase_s=slot_of[index] * self.ping_interval_s,
                frame_id=f"{frame_prefix}{index}",
                mount_radius_m=mount_radius_m,
                **ranger_options,
            )
            for index, bearing in enumerate(self.bearings_rad)
        )
        self.topics = {f"{topic_prefix}{i}": ranger for i, ranger in enumerate(self.rangers)}


def _check_sequence(sequence: tuple[int, ...], count: int) -> None:
    if sorted(sequence) != list(range(count)):
        raise ValueError(
            f"activation_sequence must fire each of the {count} rangers exactly once "
            f"(a permutation of 0..{count - 1}), got {tuple(sequence)}."
        )
    for slot, index in enumerate(sequence):
        following = sequence[(slot + 1) % count]  # wraps: the next cycle starts right after
        if count > 2 and abs(index - following) == 1:
            raise ValueError(
                f"activation_sequence fires neighbours {index} and {following} back to back, so "
                "the second would hear the first's echo; reorder it so consecutive pings are at "
                "least two places apart."
            )
