// The files a collider may come from, read into geometry: a greyscale PNG as a heightfield (stb), a triangle
// mesh from OBJ (tinyobjloader) or PLY (core/ply.h). Errors name the scene file and the collider's key.
#pragma once

#include <string>

#include "core/ply.h"
#include "geometry/collider_shape.h"

namespace surge {

// An 8- or 16-bit PNG (grey, or colour read as its luminance) as heights 0 (black) to `height` (white) over
// sizeX x sizeZ metres. Throws InputError(where, key) if it cannot be read or is smaller than 2 x 2 pixels.
Heightfield readHeightfieldPng(const std::string& file, float sizeX, float sizeZ, float height,
                               const std::string& where, const std::string& key);

// The heightfield as a closed solid: its surface, skirts down to `bottom` and a floor, with at most one vertex
// per `spacing` along each axis (the image is sampled, not every pixel drawn).
TriangleMesh heightfieldMesh(const Heightfield& heightfield, float bottom, float spacing);

// A triangle mesh from an .obj or .ply file (by extension; polygons are fanned into triangles).
TriangleMesh readMeshFile(const std::string& file, const std::string& where, const std::string& key);

}  // namespace surge
