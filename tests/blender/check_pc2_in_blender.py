"""Blender imports clothsim's point cache as docs/animation_tools.md says, and shows the run's frames.

Run by Blender: blender -b --factory-startup --python check_pc2_in_blender.py -- RUN_DIR
RUN_DIR holds cache.pc2, cache_rest.obj and frames/mesh_NNNN.obj. The rest mesh is imported with
the OBJ importer, a Mesh Cache modifier (PC2, scene play mode, frame start 1) is added, and at each
scene frame k + 1 the evaluated mesh in world space must equal the run's frame k to float
precision, vertex for vertex: once with the axes kept as they are (forward Y, up Z), once with the
importer's defaults (forward -Z, up Y); the modifier's axes stay at their defaults both times. Prints "blender pc2 check passed" and exits 0;
exits 1 on a mismatch.
"""
import glob
import os
import sys

import bpy

run_dir = sys.argv[sys.argv.index("--") + 1]


def read_obj_vertices(path):
    with open(path) as f:
        return [tuple(float(x) for x in line.split()[1:4]) for line in f if line.startswith("v ")]


# (importer forward, importer up, modifier forward, modifier up, OBJ point -> Blender world point):
# the axes as they are, and the importer's defaults (a y-up scene stands upright in Blender's z-up
# world). Either way the modifier keeps its default axes (+Y forward, +Z up): the importer turns
# the object, not its vertices, so the cache's positions are already in the object's own axes.
setups = [
    ("Y", "Z", "POS_Y", "POS_Z", lambda p: p),
    ("NEGATIVE_Z", "Y", "POS_Y", "POS_Z", lambda p: (p[0], -p[2], p[1])),
]
frames = sorted(glob.glob(os.path.join(run_dir, "frames", "mesh_*.obj")))
worst = 0.0
for forward, up, mod_forward, mod_up, convert in setups:
    bpy.ops.object.select_all(action="SELECT")
    bpy.ops.object.delete()
    bpy.ops.wm.obj_import(filepath=os.path.join(run_dir, "cache_rest.obj"), forward_axis=forward, up_axis=up)
    obj = bpy.context.selected_objects[0]
    mod = obj.modifiers.new("cache", "MESH_CACHE")
    mod.cache_format = "PC2"
    mod.filepath = os.path.join(run_dir, "cache.pc2")
    mod.forward_axis = mod_forward
    mod.up_axis = mod_up
    mod.play_mode = "SCENE"
    mod.time_mode = "FRAME"
    mod.frame_start = 1.0
    mod.frame_scale = 1.0
    for k, path in enumerate(frames):
        bpy.context.scene.frame_set(k + 1)
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        mesh = evaluated.to_mesh()
        expected = [convert(p) for p in read_obj_vertices(path)]
        if len(mesh.vertices) != len(expected):
            print(f"frame {k}: {len(mesh.vertices)} vertices in Blender, {len(expected)} in {path}")
            sys.exit(1)
        world = obj.matrix_world
        for v, e in zip(mesh.vertices, expected):
            w = world @ v.co
            worst = max(worst, max(abs(a - b) for a, b in zip(w, e)))
        evaluated.to_mesh_clear()
print(f"{len(frames)} frames, 2 axis set-ups, largest difference {worst:.3g} m")
if worst > 1e-5:
    print("blender pc2 check failed")
    sys.exit(1)
print("blender pc2 check passed")
