"""The world file format: a TOML table checked key by key and expanded into plain geometry.

`parse_world_spec(data, source)` turns the dict `tomllib` reads from `server/sim/worlds/<id>.toml`
into a `WorldSpec`: every number checked (type, finite, range), every unknown or missing key
reported by name, and the generators expanded (boxes into four edges, `[[plant_rows]]` into
cylinders, `[[tape]]` polylines with rounded corners into short segments). `server.sim.world`
compiles a spec into numpy arrays and rasterizes the map. Nothing here reads files or a clock.

A mistake raises `WorldError` naming the world, the field and what to do, e.g.
"world 'office': walls[3].x2: expected a number in metres, got 'abc'".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from server.sim.world_shapes import (
    DEFAULT_TAPE_MAX_SEGMENT_M,
    box_edges,
    plant_row,
    tape_path,
)
from server.sim.world_shapes import Problem as _Problem

KNOWN_ROBOT_IDS: tuple[str, ...] = (
    "crowbot",
    "crop_rover",
    "ir_scout",
    "turtlebot",
    "turtlebot3",
)
CYLINDER_KINDS: tuple[str, ...] = ("plant", "post")


class WorldError(ValueError):
    """A world file or world id is wrong; the message names the field and the fix."""


_REQUIRED = object()


def _show(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value)


@dataclass(frozen=True)
class _Number:
    """A finite TOML number. `low`/`high` bound it; `low_open` makes the low bound strict."""

    unit: str  # how the expected value is described: "metres", "degrees", ...
    low: float | None = None
    low_open: bool = False
    high: float | None = None
    integer: bool = False

    def parse(self, value: Any, where: str) -> float | int:
        kind = "an integer" if self.integer else "a number"
        ok_types = (int,) if self.integer else (int, float)
        if isinstance(value, bool) or not isinstance(value, ok_types):
            raise _Problem(f"{where}: expected {kind} in {self.unit}, got {_show(value)}")
        if not math.isfinite(value):
            raise _Problem(f"{where} must be a finite number (got {value})")
        if self.low is not None and (value <= self.low if self.low_open else value < self.low):
            raise _Problem(
                f"{where} must be {'>' if self.low_open else '>='} {self.low:g} (got {value})"
            )
        if self.high is not None and value > self.high:
            raise _Problem(f"{where} must be <= {self.high:g} (got {value})")
        return int(value) if self.integer else float(value)


@dataclass(frozen=True)
class _Text:
    choices: tuple[str, ...] = ()

    def parse(self, value: Any, where: str) -> str:
        if not isinstance(value, str):
            raise _Problem(f"{where}: expected a string, got {_show(value)}")
        if self.choices and value not in self.choices:
            raise _Problem(f"{where}: expected one of {', '.join(self.choices)}, got {value!r}")
        return value


@dataclass(frozen=True)
class _Bool:
    def parse(self, value: Any, where: str) -> bool:
        if not isinstance(value, bool):
            raise _Problem(f"{where}: expected true or false, got {_show(value)}")
        return value


@dataclass(frozen=True)
class _List:
    """A TOML array of `item`s, at least `min_len` long."""

    item: Any
    min_len: int = 0
    what: str = "an array"

    def parse(self, value: Any, where: str) -> list:
        if not isinstance(value, list):
            raise _Problem(f"{where}: expected {self.what}, got {_show(value)}")
        if len(value) < self.min_len:
            raise _Problem(f"{where}: needs at least {self.min_len} entries (got {len(value)})")
        return [self.item.parse(v, f"{where}[{i}]") for i, v in enumerate(value)]


_METRES = _Number("metres")
_POSITIVE_M = _Number("metres", low=0.0, low_open=True)
_NONNEG_M = _Number("metres", low=0.0)
_DEGREES = _Number("degrees")
_FRACTION = _Number("the range 0..1", low=0.0, high=1.0)
_POINT = _List(_METRES, what="a point [x, y] in metres")
_POINTS = _List(_POINT, min_len=2, what="an array of points [[x, y], ...] in metres")

# Every table's keys in the order error messages list them; _REQUIRED marks keys without default.
_BOUNDS = {k: (_METRES, _REQUIRED) for k in ("min_x", "min_y", "max_x", "max_y")}
_SPAWN = {
    "name": (_Text(), _REQUIRED),
    "x": (_METRES, _REQUIRED),
    "y": (_METRES, _REQUIRED),
    "yaw_deg": (_DEGREES, 0.0),
}
_WALL = {
    "x1": (_METRES, _REQUIRED),
    "y1": (_METRES, _REQUIRED),
    "x2": (_METRES, _REQUIRED),
    "y2": (_METRES, _REQUIRED),
    "height": (_POSITIVE_M, 0.5),
}
_BOX = {
    "x": (_METRES, _REQUIRED),
    "y": (_METRES, _REQUIRED),
    "width": (_POSITIVE_M, _REQUIRED),
    "depth": (_POSITIVE_M, _REQUIRED),
    "yaw_deg": (_DEGREES, 0.0),
    "height": (_POSITIVE_M, 0.5),
}
_CYLINDER = {
    "x": (_METRES, _REQUIRED),
    "y": (_METRES, _REQUIRED),
    "radius": (_POSITIVE_M, _REQUIRED),
    "height": (_POSITIVE_M, 0.5),
    "kind": (_Text(CYLINDER_KINDS), "post"),
}
_PLANT_ROW = {
    "start": (_POINT, _REQUIRED),
    "end": (_POINT, _REQUIRED),
    "spacing": (_POSITIVE_M, _REQUIRED),
    "radius": (_POSITIVE_M, _REQUIRED),
    "height": (_POSITIVE_M, 0.4),
    "gaps": (_List(_Number("plant indices", low=0, integer=True)), []),
    "jitter": (_NONNEG_M, 0.0),
    "seed": (_Number("integers", integer=True), 0),
}
_LIGHT = {
    "name": (_Text(), _REQUIRED),
    "x": (_METRES, _REQUIRED),
    "y": (_METRES, _REQUIRED),
    "z": (_NONNEG_M, 0.1),
    "intensity": (_Number("relative units", low=0.0), 1.0),
    "movable": (_Bool(), False),
}
_TAPE = {
    "points": (_POINTS, _REQUIRED),
    "width": (_POSITIVE_M, _REQUIRED),
    "darkness": (_FRACTION, 1.0),
    "closed": (_Bool(), False),
    "corner_radius": (_NONNEG_M, 0.0),
    "max_segment": (_POSITIVE_M, DEFAULT_TAPE_MAX_SEGMENT_M),
}
_MAP = {
    "resolution": (_Number("metres per cell", low=0.0, low_open=True), _REQUIRED),
    "origin": (
        _List(
            _Number("metres (yaw in radians)"), min_len=3, what="[x, y, yaw] in metres and radians"
        ),
        None,
    ),
    "source": (_Text(("geometry",)), None),
    "rows": (_List(_Text(), min_len=1), None),
    "width": (_Number("cells", low=1, integer=True), None),
    "height": (_Number("cells", low=1, integer=True), None),
}
_LISTS = {
    "spawns": _SPAWN,
    "walls": _WALL,
    "boxes": _BOX,
    "cylinders": _CYLINDER,
    "plant_rows": _PLANT_ROW,
    "lights": _LIGHT,
    "tape": _TAPE,
}
_TOP = (
    "id",
    "title",
    "description",
    "robots",
    "ambient_light",
    "floor_reflectance",
    "bounds",
    *_LISTS,
    "map",
)
MAP_CELL_CHARS = {".": 0, "#": 100, "?": -1}  # inline map rows, written top (max y) row first


@dataclass(frozen=True)
class WorldSpec:
    """A checked, expanded world file; plain Python values, compiled by `server.sim.world`."""

    id: str
    title: str
    description: str
    robots: tuple[str, ...]
    bounds: tuple[float, float, float, float]  # min_x, min_y, max_x, max_y [m]
    ambient_light: float
    floor_reflectance: float
    spawns: list[tuple[str, float, float, float]]  # name, x [m], y [m], yaw [rad]
    segments: list[tuple[float, float, float, float, float]]  # x1, y1, x2, y2, height [m]
    boxes: list[tuple[float, float, float, float, float, float]]  # x, y, w, d, yaw [rad], h [m]
    circles: list[tuple[float, float, float, float, str]]  # x, y, radius, height [m], kind
    tape: list[tuple[float, float, float, float, float, float]]  # x1, y1, x2, y2, width, dark
    lights: list[tuple[str, float, float, float, float, bool]]
    map: dict[str, Any] | None  # resolution, origin (x, y, yaw), width, height, rows | None


def _table(value: Any, fields: dict, where: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise _Problem(f"{where}: expected a table, got {_show(value)}")
    for key in value:
        if key not in fields:
            raise _Problem(f"{where}: unknown key {key!r} (valid: {', '.join(fields)})")
    out = {}
    for key, (kind, default) in fields.items():
        if key in value:
            out[key] = kind.parse(value[key], f"{where}.{key}")
        elif default is _REQUIRED:
            raise _Problem(f"{where}: missing required key {key!r} (valid: {', '.join(fields)})")
        else:
            out[key] = default
    return out


def _tables(data: dict, name: str) -> list[dict[str, Any]]:
    value = data.get(name, [])
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise _Problem(
            f"{name}: expected an array of tables written [[{name}]], got {_show(value)}"
        )
    return [_table(v, _LISTS[name], f"{name}[{i}]") for i, v in enumerate(value)]


def _map(raw: Any, bounds: tuple[float, float, float, float]) -> dict[str, Any]:
    spec = _table(raw, _MAP, "map")
    if (spec["source"] is None) == (spec["rows"] is None):
        raise _Problem(
            'map: give either source = "geometry" or rows = ["#..#", ...], not both or neither'
        )
    origin = spec["origin"] if spec["origin"] is not None else [bounds[0], bounds[1], 0.0]
    if len(origin) != 3:
        raise _Problem(f"map.origin: expected [x, y, yaw], got {len(origin)} numbers")
    out = {"resolution": spec["resolution"], "origin": tuple(origin), "rows": None}
    res = spec["resolution"]
    if spec["rows"] is not None:
        if spec["width"] is not None or spec["height"] is not None:
            raise _Problem("map: width and height come from rows; remove them")
        widths = {len(r) for r in spec["rows"]}
        if len(widths) != 1:
            raise _Problem(f"map.rows: every row must have the same length (got {sorted(widths)})")
        for i, row in enumerate(spec["rows"]):
            bad = set(row) - set(MAP_CELL_CHARS)
            if bad:
                raise _Problem(
                    f"map.rows[{i}]: unknown cell {sorted(bad)[0]!r} (use '.' free, "
                    "'#' occupied, '?' unknown)"
                )
        out.update(rows=list(spec["rows"]), width=widths.pop(), height=len(spec["rows"]))
    else:
        out["width"] = spec["width"] or max(1, math.ceil((bounds[2] - origin[0]) / res - 1e-9))
        out["height"] = spec["height"] or max(1, math.ceil((bounds[3] - origin[1]) / res - 1e-9))
    return out


def parse_world_spec(
    data: dict[str, Any], source: str, known_robot_ids: tuple[str, ...] = KNOWN_ROBOT_IDS
) -> WorldSpec:
    """Check a world file's dict and expand its generators; raise `WorldError` on any mistake.

    `source` names the file in messages until the world's own id is known.
    """
    label = f"file {source}"
    try:
        if not isinstance(data, dict):
            raise _Problem(f"expected a TOML table, got {type(data).__name__}")
        for key in data:
            if key not in _TOP:
                raise _Problem(f"unknown top-level key {key!r} (valid: {', '.join(_TOP)})")
        for key in ("id", "title", "robots", "bounds", "spawns"):
            if key not in data:
                raise _Problem(f"missing required key {key!r}")
        world_id = _Text().parse(data["id"], "id")
        if not world_id.isidentifier() or world_id != world_id.lower():
            raise _Problem(f"id: {world_id!r} must be a lowercase identifier like 'office'")
        label = repr(world_id)
        robots = _List(_Text(), min_len=1, what="an array of robot ids").parse(
            data["robots"], "robots"
        )
        for i, robot in enumerate(robots):
            if robot not in known_robot_ids:
                raise _Problem(
                    f"robots[{i}]: unknown robot id {robot!r} (valid: {', '.join(known_robot_ids)})"
                )
        b = _table(data["bounds"], _BOUNDS, "bounds")
        bounds = (b["min_x"], b["min_y"], b["max_x"], b["max_y"])
        if not (bounds[0] < bounds[2] and bounds[1] < bounds[3]):
            raise _Problem(f"bounds: min_x < max_x and min_y < max_y needed (got {bounds})")
        spawns = []
        for i, s in enumerate(_tables(data, "spawns")):
            if not (bounds[0] < s["x"] < bounds[2] and bounds[1] < s["y"] < bounds[3]):
                raise _Problem(
                    f"spawns[{i}] {s['name']!r} at ({s['x']}, {s['y']}) is outside "
                    f"bounds x {bounds[0]}..{bounds[2]}, y {bounds[1]}..{bounds[3]}; "
                    "move it inside or widen [bounds]"
                )
            if s["name"] in [name for name, *_ in spawns]:
                raise _Problem(f"spawns[{i}]: name {s['name']!r} is used twice; rename one")
            spawns.append((s["name"], s["x"], s["y"], math.radians(s["yaw_deg"])))
        if not spawns:
            raise _Problem("spawns: add at least one [[spawns]] (the first is the default)")
        segments = []
        for i, w in enumerate(_tables(data, "walls")):
            if w["x1"] == w["x2"] and w["y1"] == w["y2"]:
                raise _Problem(f"walls[{i}]: both ends are the same point; give it a length")
            segments.append((w["x1"], w["y1"], w["x2"], w["y2"], w["height"]))
        boxes = []
        for bx in _tables(data, "boxes"):
            boxes.append(
                (
                    bx["x"],
                    bx["y"],
                    bx["width"],
                    bx["depth"],
                    math.radians(bx["yaw_deg"]),
                    bx["height"],
                )
            )
            edges = box_edges(
                bx["x"], bx["y"], bx["width"], bx["depth"], math.radians(bx["yaw_deg"])
            )
            segments += [(*edge, bx["height"]) for edge in edges]
        circles = [
            (c["x"], c["y"], c["radius"], c["height"], c["kind"])
            for c in _tables(data, "cylinders")
        ]
        for i, row in enumerate(_tables(data, "plant_rows")):
            circles += plant_row(row, f"plant_rows[{i}]")
        tape = []
        for i, t in enumerate(_tables(data, "tape")):
            tape += tape_path(t, f"tape[{i}]")
        lights = []
        for i, lt in enumerate(_tables(data, "lights")):
            if lt["name"] in [name for name, *_ in lights]:
                raise _Problem(f"lights[{i}]: name {lt['name']!r} is used twice; rename one")
            lights.append((lt["name"], lt["x"], lt["y"], lt["z"], lt["intensity"], lt["movable"]))
        grid = _map(data["map"], bounds) if "map" in data else None
        return WorldSpec(
            id=world_id,
            title=_Text().parse(data["title"], "title"),
            description=_Text().parse(data.get("description", ""), "description"),
            robots=tuple(robots),
            bounds=bounds,
            ambient_light=_FRACTION.parse(data.get("ambient_light", 0.3), "ambient_light"),
            floor_reflectance=_FRACTION.parse(
                data.get("floor_reflectance", 0.7), "floor_reflectance"
            ),
            spawns=spawns,
            segments=segments,
            boxes=boxes,
            circles=circles,
            tape=tape,
            lights=lights,
            map=grid,
        )
    except _Problem as problem:
        raise WorldError(f"world {label}: {problem}") from None
