// A run's motion as a point cache for animation tools (docs/animation_tools.md): Blender's Mesh
// Cache modifier and Houdini read PC2 files. Built from the OBJ frames of a run
// (RUN/frames/mesh_NNNN.obj, all of one mesh), it writes
//   RUN/cache.pc2        the PC2 point cache: a 32-byte header — the 12 bytes "POINTCACHE2\0",
//                        int32 version 1, int32 number of points, float32 start frame (0), float32
//                        sample rate (1: one sample per frame), int32 number of samples — then,
//                        sample after sample, every point's x, y, z as float32, little-endian
//   RUN/cache_rest.obj   the mesh of the first frame with per-vertex normals (area-weighted) and
//                        the frames' texture coordinates when they have them: the object the cache
//                        is applied to (same vertices in the same order)
// Each file is written through a temporary sibling and renamed into place: whole or absent.
#pragma once

#include <filesystem>

namespace clothsim {

struct PointCacheReport {
  int frames = 0;  // samples written
  int points = 0;  // vertices per sample
};

// Builds cache.pc2 and cache_rest.obj in `run_dir` from its frames/mesh_NNNN.obj. Throws
// std::runtime_error naming the file: no frames, a frame that cannot be read, or frames whose
// vertex count or triangles differ from the first's.
PointCacheReport write_point_cache(const std::filesystem::path& run_dir);

}  // namespace clothsim
