"""Blender's cloth on a garment drop, for bench/garment_drop.py (the peer of clothsim's drop).

Run by Blender 3.4: blender -b --factory-startup --python blender_cloth_drop.py -- \
    MESH.obj OUT.obj DT END THICKNESS AREAL_DENSITY SELF(0|1) BALL_RADIUS BALL_Y [QUALITY]

MESH.obj is the garment as clothsim starts it (y up, metres: its frame 0 at obj_level 0, the
limit points of the control vertices joined by the control triangles, so both simulators move the
same vertices). The scene is clothsim's `tshirt_drop`: gravity 9.81 m/s² along −y, a ball of
radius BALL_RADIUS centred at (0, BALL_Y, 0) and the ground plane y = 0, both colliders. Blender's
cloth (default material: its tension, compression, shear and bending stiffness 15/15/15/0.5,
air damping 1) gets the vertex mass that gives AREAL_DENSITY [kg/m²] over the mesh's area, the
collision distance THICKNESS [m] against the colliders and, with SELF = 1, self-collision at the
same distance. The frame rate and the steps per frame ("quality") make the step DT [s]: quality
QUALITY (default: Blender's 5) at a frame rate of 1 / (QUALITY · DT), or, where that is not a whole
number of frames per second, the quality that makes one (reported).

The cloth is simulated over END [s] by stepping the scene's frames; the wall time of that loop
alone is printed as a JSON line: {"seconds": ..., "steps": ..., "frames": ..., "vertices": ...,
"quality": ..., "fps": ...}. The last frame's evaluated mesh is written to OUT.obj in clothsim's
axes (y up). Exits 1 with a message on bad arguments.
"""
import json
import math
import sys
import time

import bpy


def fail(message):
    print("blender_cloth_drop: " + message, file=sys.stderr)
    sys.exit(1)


args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if len(args) not in (9, 10):
    fail("usage: MESH.obj OUT.obj DT END THICKNESS AREAL_DENSITY SELF BALL_RADIUS BALL_Y [QUALITY]")
mesh_path, out_path = args[0], args[1]
dt, end, thickness, density = (float(a) for a in args[2:6])
self_collision = args[6] == "1"
ball_radius, ball_y = float(args[7]), float(args[8])
quality = int(args[9]) if len(args) == 10 else 5
if not (dt > 0 and end > 0 and thickness > 0 and density > 0 and quality > 0):
    fail("DT, END, THICKNESS, AREAL_DENSITY and QUALITY must be > 0")

# A whole number of frames per second: fps = 1 / (quality · dt), with the quality raised until it is.
fps = 1.0 / (quality * dt)
while abs(fps - round(fps)) > 1e-9 and quality < 1000:
    quality += 1
    fps = 1.0 / (quality * dt)
if abs(fps - round(fps)) > 1e-9 or round(fps) < 1:
    fail(f"no whole frame rate for dt = {dt}")
fps = int(round(fps))

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = fps
scene.render.fps_base = 1.0
frames = int(round(end * fps))
scene.frame_start = 1
scene.frame_end = frames + 1

# clothsim's (x, y, z) with y up is Blender's (x, −z, y) with z up: the importer's defaults.
bpy.ops.wm.obj_import(filepath=mesh_path, forward_axis="NEGATIVE_Z", up_axis="Y")
cloth = bpy.context.selected_objects[0]
me = cloth.data
area = sum(p.area for p in me.polygons)
n = len(me.vertices)

mod = cloth.modifiers.new("cloth", "CLOTH")
s = mod.settings
s.quality = quality
s.mass = density * area / n
s.time_scale = 1.0
c = mod.collision_settings
c.use_collision = True
c.distance_min = thickness
c.use_self_collision = self_collision
c.self_distance_min = thickness
mod.point_cache.frame_start = 1
mod.point_cache.frame_end = frames + 1

bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=ball_radius, location=(0.0, 0.0, ball_y))
ball = bpy.context.active_object
ball.modifiers.new("collision", "COLLISION")
ball.collision.thickness_outer = 0.001
bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 0.0, 0.0))
ground = bpy.context.active_object
ground.modifiers.new("collision", "COLLISION")
ground.collision.thickness_outer = 0.001

scene.frame_set(1)
start = time.perf_counter()
for f in range(2, frames + 2):
    scene.frame_set(f)
seconds = time.perf_counter() - start

depsgraph = bpy.context.evaluated_depsgraph_get()
evaluated = cloth.evaluated_get(depsgraph)
mesh = evaluated.to_mesh()
world = cloth.matrix_world
with open(out_path, "w") as f:
    f.write(f"# Blender {bpy.app.version_string} cloth, frame {frames + 1} (t = {frames / fps} s), clothsim's axes\n")
    for v in mesh.vertices:
        p = world @ v.co
        f.write(f"v {p.x:.9g} {p.z:.9g} {-p.y:.9g}\n")
    for poly in mesh.polygons:
        f.write("f " + " ".join(str(i + 1) for i in poly.vertices) + "\n")
evaluated.to_mesh_clear()
print(json.dumps({"seconds": seconds, "steps": frames * quality, "frames": frames, "vertices": n, "quality": quality,
                  "fps": fps, "vertex_mass": s.mass, "area": area}))
