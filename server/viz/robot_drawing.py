"""The robot in the scene: body, wheels, a nose that shows its heading, its four LEDs in the colour
last sent on `Leds`, a buzzer indicator while `Buzzer` sounds, and a small block at every sensor
frame (the IR ranger turns with its servo because its frame does).

Sizes come from the robot's `RobotGeometry` (server/sim/robots/base.py). Everything hangs below one
frame node, /robot, so a new pose is one position and one orientation message; colours and
visibility are sent only when they change (viser keeps the latest of each anyway).

The TurtleBot3 Burger gets its own recognisable body (`burger_body`): two stacked octagonal
plates on the waffle-plate footprint, the LDS-01 on top, behind the wheel axle as on the robot
(turtlebot3_description's URDF puts the body and the scanner 32 mm behind base_link).
"""

from __future__ import annotations

import math

from server.sim.robots.base import RobotModel
from server.viz.meshes import transformed, unit_box, unit_cylinder, yaw_wxyz
from server.viz.view_state import SensorFrame

ROBOT_NODE = "/robot"
# A saturated blue no floor, wall, furniture or overlay uses, dark enough for a 3:1 contrast on
# the light floor (world_scene.py): the robot is found at a glance, and by the e2e test.
BODY_RGB = (30, 80, 215)
NOSE_RGB = (250, 250, 250)
WHEEL_RGB = (30, 30, 30)
LED_OFF_RGB = (45, 45, 45)  # an unlit LED is dark plastic, not black paint
BUZZER_RGB = (255, 200, 0)
SENSOR_RGB = (235, 120, 20)  # sensor housings: orange on the blue body
# Frames that hold a sensor worth a housing (not imu_link or base_footprint: inside the body).
SENSOR_FRAME_PREFIXES = ("ultrasonic", "camera", "laser", "base_scan", "ir")
WHEEL_WIDTH_FRACTION = 0.6  # [1] of the wheel radius: a plausible tyre width
LED_RADIUS_FRACTION = 0.07  # [1] of the body radius
LED_PLACEMENT = ((1, 1), (1, -1), (-1, 1), (-1, -1))  # corners of the top: front/back, left/right
SENSOR_BLOCK_M = 0.025  # [m] side of the block drawn at a sensor frame...
SENSOR_BLOCK_FRACTION = 0.2  # [1] ...or this much of the body radius, if smaller (the CrowBot's
# five front sensors would merge into one blob over its nose)
# TurtleBot3 Burger (URDF base_link collision box 0.140 x 0.140 x 0.143 m; LDS-01 69.5 x 95.5 x
# 39.5 mm, its URDF cylinder r = 0.055 m, 0.0315 m tall, centre 15 mm ahead of base_scan).
BURGER_PLATE_RGB = BODY_RGB  # the waffle plates (dark grey on the robot): the robots' blue
BURGER_LDS_RGB = (25, 25, 25)
BURGER_LDS_TOP_RGB = (200, 60, 40)  # the orange-red rotor cap, seen from above
BURGER_PLATE_SIDES = 8  # [-] octagons: the plates are squares with cut corners
BURGER_LAYERS_M = ((0.010, 0.085), (0.095, 0.150))  # [m] (bottom, top) of the two layers
BURGER_LDS_RADIUS_M = 0.035  # [m] round housing ~70 mm across
BURGER_LDS_AHEAD_M = 0.015  # [m] housing centre ahead of the base_scan frame
SCAN_PLANE_TOP_M = 0.192  # [m] the Burger's full height: the top of the LDS


def is_round(robot: RobotModel) -> bool:
    """A disc-shaped robot (its footprint circle is its body) is drawn as a cylinder."""
    g = robot.geometry
    return abs(g.length_m - g.width_m) < 1e-6 and abs(g.length_m / 2 - g.body_radius_m) < 0.01


def burger_body(scene, centre_x_m: float, half_length_m: float) -> None:
    """The TurtleBot3 Burger's body below /robot: two octagonal plate layers centred
    `centre_x_m` [m] ahead of the axle (negative: behind), the LDS-01 on top (module doc)."""
    plate_vertices, plate_faces = unit_cylinder(BURGER_PLATE_SIDES)
    # Rotate the octagon by half a side so its flat faces point forward, like the plates.
    half_side = math.pi / BURGER_PLATE_SIDES
    cos_turn, sin_turn = math.cos(half_side), math.sin(half_side)
    turned = plate_vertices.copy()
    turned[:, 0] = cos_turn * plate_vertices[:, 0] - sin_turn * plate_vertices[:, 1]
    turned[:, 1] = sin_turn * plate_vertices[:, 0] + cos_turn * plate_vertices[:, 1]
    radius_m = half_length_m / math.cos(half_side)  # flat faces at +-half_length
    for index, (bottom_m, top_m) in enumerate(BURGER_LAYERS_M):
        scene.add_mesh_simple(
            f"{ROBOT_NODE}/body" if index == 0 else f"{ROBOT_NODE}/body_{index}",
            transformed(
                turned,
                (radius_m, radius_m, top_m - bottom_m),
                (centre_x_m, 0.0, (bottom_m + top_m) / 2),
            ),
            plate_faces,
            color=BURGER_PLATE_RGB,
        )
    lds_vertices, lds_faces = unit_cylinder()
    lds_bottom_m = BURGER_LAYERS_M[-1][1]
    lds_top_m = SCAN_PLANE_TOP_M
    lds_x_m = centre_x_m + BURGER_LDS_AHEAD_M
    scene.add_mesh_simple(
        f"{ROBOT_NODE}/lds",
        transformed(
            lds_vertices,
            (BURGER_LDS_RADIUS_M, BURGER_LDS_RADIUS_M, lds_top_m - lds_bottom_m),
            (lds_x_m, 0.0, (lds_bottom_m + lds_top_m) / 2),
        ),
        lds_faces,
        color=BURGER_LDS_RGB,
    )
    scene.add_mesh_simple(
        f"{ROBOT_NODE}/lds_cap",
        transformed(
            lds_vertices,
            (0.6 * BURGER_LDS_RADIUS_M, 0.6 * BURGER_LDS_RADIUS_M, 0.004),
            (lds_x_m, 0.0, lds_top_m + 0.002),
        ),
        lds_faces,
        color=BURGER_LDS_TOP_RGB,
    )


class RobotDrawing:
    """Adds the robot below /robot in `scene`; `update()` moves and recolours it."""

    def __init__(self, scene, robot: RobotModel) -> None:
        self.scene = scene
        self.robot = robot
        g = robot.geometry
        self.clearance_m = 0.5 * g.wheel_radius_m  # [m] the body's underside above the floor
        body_height_m = max(g.height_m - self.clearance_m, 0.01)
        self.root = scene.add_frame(ROBOT_NODE, show_axes=False)
        centre_x = g.body_offset_x_m  # [m] the body's centre relative to the wheel axle
        nose_z = g.height_m + 0.002  # [m] on the top
        if robot.id == "turtlebot3":
            burger_body(scene, centre_x, g.length_m / 2)
            nose_z = BURGER_LAYERS_M[-1][1] + 0.002  # on the top plate, in front of the LDS
        else:
            if is_round(robot):
                vertices, faces = unit_cylinder()
                radius = g.body_radius_m
                scale = (radius, radius, body_height_m)
            else:
                vertices, faces = unit_box()
                scale = (g.length_m, g.width_m, body_height_m)
            offset = (centre_x, 0.0, self.clearance_m + body_height_m / 2)
            scene.add_mesh_simple(
                f"{ROBOT_NODE}/body", transformed(vertices, scale, offset), faces, color=BODY_RGB
            )
        half_length = g.length_m / 2
        scene.add_box(
            f"{ROBOT_NODE}/nose",
            color=NOSE_RGB,
            dimensions=(0.25 * half_length, 0.3 * g.width_m, 0.004),
            position=(centre_x + 0.75 * half_length, 0.0, nose_z),
        )
        wheel_vertices, wheel_faces = unit_cylinder()
        wheel_width_m = WHEEL_WIDTH_FRACTION * g.wheel_radius_m
        for side, sign in (("left", 1.0), ("right", -1.0)):
            scene.add_mesh_simple(
                f"{ROBOT_NODE}/wheel_{side}",
                transformed(
                    wheel_vertices,
                    (g.wheel_radius_m, g.wheel_radius_m, wheel_width_m),
                    (0.0, sign * g.track_m / 2, g.wheel_radius_m),
                    swap_yz=True,
                ),
                wheel_faces,
                color=WHEEL_RGB,
            )
        self.leds = []
        if "Leds" in robot.commands:
            reach = 0.5 * g.body_radius_m  # [m] LEDs at the corners of the top, inside the rim
            for index, (forward, left) in enumerate(LED_PLACEMENT):
                self.leds.append(
                    scene.add_icosphere(
                        f"{ROBOT_NODE}/led_{index}",
                        radius=LED_RADIUS_FRACTION * g.body_radius_m,
                        color=LED_OFF_RGB,
                        position=(forward * reach, left * reach, g.height_m),
                    )
                )
        self.buzzer = None
        if "Buzzer" in robot.commands:
            self.buzzer = scene.add_icosphere(
                f"{ROBOT_NODE}/buzzer",
                radius=0.3 * g.body_radius_m,
                color=BUZZER_RGB,
                opacity=0.6,
                position=(0.0, 0.0, g.height_m + 0.4 * g.body_radius_m),
                visible=False,
            )
        self.sensor_blocks: dict[str, object] = {}
        self._shown: dict[str, object] = {}
        # The sensors the robot declares a fixed frame for (the TurtleBot's ultrasonic ring and
        # depth camera, the rover's laser), drawn from the start; a frame /tf moves (the IR
        # ranger's servo) is drawn and moved by update().
        for frame, mount in robot.frames.items():
            if frame.startswith(SENSOR_FRAME_PREFIXES):
                x, y, heading = mount[0], mount[1], mount[2]
                self._sensor_block(frame, SensorFrame(x, y, heading, 1.0))
        # Sensors mounted without a frame of their own (the CrowBot's ultrasonic ranger and its
        # light and line sensors): a housing at each mount.
        for topic, sensor in robot.build_sensors().items():
            mounts = getattr(sensor, "mounts", None) or (
                (sensor.mount,) if hasattr(sensor, "mount") else ()
            )
            for index, mount in enumerate(mounts):
                self._sensor_block(
                    f"{topic}_{index}", SensorFrame(mount.x_m, mount.y_m, mount.yaw_rad, 1.0)
                )

    def _changed(self, key: str, value: object) -> bool:
        if self._shown.get(key) == value:
            return False
        self._shown[key] = value
        return True

    def update(
        self,
        pose: tuple[float, float, float] | None,
        leds_rgb: tuple[int, int, int] | None,
        buzzer_on: bool,
        sensor_frames: dict[str, SensorFrame],
    ) -> None:
        """Pose (x [m], y [m], yaw [rad]); LED colour (None: never set); buzzer; sensor frames
        in the robot frame."""
        if pose is not None and self._changed("pose", pose):
            x, y, yaw = pose
            self.root.position = (x, y, 0.0)
            self.root.wxyz = yaw_wxyz(yaw)
        colour = LED_OFF_RGB if leds_rgb is None or not any(leds_rgb) else tuple(leds_rgb)
        if self.leds and self._changed("leds", colour):
            for led in self.leds:
                led.color = colour
        if self.buzzer is not None and self._changed("buzzer", buzzer_on):
            self.buzzer.visible = buzzer_on
        for frame, mount in sensor_frames.items():
            self._sensor_block(frame, mount)

    def _sensor_block(self, frame: str, mount: SensorFrame) -> None:
        """A sensor's housing at its frame, on the body's rim (inside it, it would not show)."""
        side_m = min(SENSOR_BLOCK_M, SENSOR_BLOCK_FRACTION * self.robot.geometry.body_radius_m)
        block = self.sensor_blocks.get(frame)
        if block is None:
            block = self.scene.add_box(
                f"{ROBOT_NODE}/sensors/{frame}",
                color=SENSOR_RGB,
                dimensions=(side_m, side_m, side_m / 2),
            )
            self.sensor_blocks[frame] = block
        if self._changed(f"frame:{frame}", mount):
            block.position = (mount.x, mount.y, self.robot.geometry.height_m + side_m / 4)
            block.wxyz = yaw_wxyz(mount.heading)
