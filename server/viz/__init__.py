"""The 3D view of a run (viser), one concept per module:

- `manager.py`: one ViserServer per watched run on a loopback port, started on demand, stopped
  when idle; a live run turns into its replay when it ends.
- `view.py`: one run's scene put together (lighting, panel), and its controls (click a goal,
  drag a light); `camera.py`: the camera on the robot, following it, framing the world;
  `layers.py`: the panel's layer toggles.
- `world_scene.py`: the world (floor, walls, boxes, plants, tape, occupancy map);
  `lights.py`: the light sources; `robot_drawing.py`: the robot; `overlays.py`: rays, trail,
  path, lookahead, goal; `meshes.py`: the unit shapes they share.
- `view_state.py`: the fold from messages to what is shown, one for live and replay;
  `rays.py`: sensor readings as world geometry.
- `live.py`: a live run followed through its telemetry; `recording.py` and `replay.py`: a
  finished run's recording read back and played with a time slider.

The web side (the proxy, auth) is server/api/routes/viz.py; nothing here knows about HTTP.
"""
