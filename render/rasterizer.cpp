#include "render/rasterizer.h"

// clang-format off
#include <GL/osmesa.h>
#include <GL/gl.h>
// clang-format on

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/shading.h"

namespace surge {

namespace {

using Vec3 = Eigen::Vector3f;
using Rgba = std::array<uint8_t, 4>;

constexpr int kSupersample = 2;  // drawn at 2x and averaged down: anti-aliased edges

Rgba display(const Vec3& linear, float exposure) {
  return {encodeSrgb(toneMap(linear.x(), exposure)), encodeSrgb(toneMap(linear.y(), exposure)),
          encodeSrgb(toneMap(linear.z(), exposure)), 255};
}

// Vertex normals: the mesh's own, or area-weighted face normals summed at each vertex.
std::vector<Vec3> vertexNormals(const TriangleMesh& mesh) {
  if (mesh.normals.size() == mesh.positions.size()) return mesh.normals;
  std::vector<Vec3> normals(mesh.positions.size(), Vec3::Zero());
  for (const auto& t : mesh.triangles) {
    const Vec3 n =
        (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    for (uint32_t v : t) normals[v] += n;
  }
  for (Vec3& n : normals) n = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitY();
  return normals;
}

// A unit sphere: an icosahedron subdivided once (42 vertices, 80 triangles).
TriangleMesh unitSphere() {
  TriangleMesh m;
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  const float p[12][3] = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (const auto& q : p) m.positions.push_back(Vec3(q[0], q[1], q[2]).normalized());
  const uint32_t f[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                             {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                             {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                             {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (const auto& tri : f) {
    uint32_t mid[3];
    for (int e = 0; e < 3; ++e) {
      mid[e] = uint32_t(m.positions.size());
      m.positions.push_back((m.positions[tri[e]] + m.positions[tri[(e + 1) % 3]]).normalized());
    }
    m.triangles.push_back({tri[0], mid[0], mid[2]});
    m.triangles.push_back({tri[1], mid[1], mid[0]});
    m.triangles.push_back({tri[2], mid[2], mid[1]});
    m.triangles.push_back({mid[0], mid[1], mid[2]});
  }
  m.normals = m.positions;  // duplicated edge midpoints are harmless for drawing
  return m;
}

}  // namespace

struct Rasterizer::Impl {
  Scene scene;
  Shading look;
  RenderSettings settings;
  int width = 0, height = 0;  // of the GL buffer (supersampled)
  OSMesaContext context = nullptr;
  std::vector<uint8_t> buffer;
  Vec3 lo, hi;
  float size = 1;
  bool tankEdges = true;  // render.tank: the preview draws the edges for "glass" too, nothing for "none"

  // Ambient sky light on a surface facing up, as the path tracer's uniform-sky integral gives it (albedo
  // times the sky's mean radiance), and the sun on a surface with normal n.
  Vec3 diffuseLight(const Vec3& n) const {
    const Vec3 sky = 0.5f * (look.skyZenith + look.skyHorizon) * (0.6f + 0.4f * n.y());
    return sky + std::max(0.0f, n.dot(look.sunDirection)) * look.sunColor;
  }

  // Water seen at a point with normal n from direction v: Fresnel blend of the reflected sky and the body
  // colour (the floor lit by sun and sky seen through about half a metre of water), plus the sun's highlight.
  Vec3 waterColour(const Vec3& v, Vec3 n) const { return waterColour(v, n, look.waterAbsorption); }
  Vec3 waterColour(const Vec3& v, Vec3 n, const Vec3& absorption) const {
    if (n.dot(v) > 0) n = -n;
    const float c = std::clamp(-v.dot(n), 0.0f, 1.0f), m = 1.0f - c;
    const float fresnel = 0.02f + 0.98f * m * m * m * m * m;
    const Vec3 reflected = v - 2.0f * v.dot(n) * n;
    const Vec3 body = look.floorAlbedo * 0.55f *
                      absorption.unaryExpr([](float a) { return std::exp(-0.5f * a); })
                          .cwiseProduct(diffuseLight(Vec3::UnitY()));
    const float highlight = std::pow(std::max(reflected.dot(look.sunDirection), 0.0f), 400.0f);
    return (1.0f - fresnel) * body + fresnel * skyRadiance(look, reflected) +
           3.0f * highlight * look.sunColor;
  }

  void begin(const PinholeCamera& camera) {
    glViewport(0, 0, width, height);
    glDisable(GL_LIGHTING);
    glDisable(GL_CULL_FACE);
    glShadeModel(GL_SMOOTH);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    if (scene.dimensions == 2) {
      // Face-on and orthographic: the tank with a margin of 8 %, fitted to the image's aspect ratio.
      const Vec3 centre = 0.5f * (lo + hi), half = 0.54f * (hi - lo);
      const float aspect = float(width) / float(height);
      const float halfW = std::max(half.x(), half.y() * aspect), halfH = halfW / aspect;
      glMatrixMode(GL_PROJECTION);
      glLoadIdentity();
      glOrtho(centre.x() - halfW, centre.x() + halfW, centre.y() - halfH, centre.y() + halfH, -100 * size,
              100 * size);
      glMatrixMode(GL_MODELVIEW);
      glLoadIdentity();
      drawTank2d();
      return;
    }
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    drawSky(camera);
    const float nearPlane = 0.01f * size, farPlane = 200.0f * size;
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glFrustum(-camera.tanHalfWidth() * nearPlane, camera.tanHalfWidth() * nearPlane,
              -camera.tanHalfHeight() * nearPlane, camera.tanHalfHeight() * nearPlane, nearPlane, farPlane);
    // World to eye: rows right, up, -forward (column-major for GL).
    const Vec3 axes[3] = {camera.right(), camera.up(), -camera.forward()};
    GLfloat m[16] = {0};
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) m[col * 4 + row] = axes[row][col];
      m[12 + row] = -axes[row].dot(camera.position());
    }
    m[15] = 1;
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixf(m);
    drawGround(camera);
    if (tankEdges) drawTankEdges();
  }

  // Everything drawn after the fluid: the colliders, and in 2D the tank's outline over all.
  void end(const PinholeCamera& camera, const std::vector<ColliderMesh>& colliders) {
    if (scene.dimensions == 2) {
      // Within the tank only, like the fluid; containers and planes first, as the ground the others stand on.
      const GLdouble tankSides[4][4] = {
          {1, 0, 0, -lo.x()}, {-1, 0, 0, hi.x()}, {0, 1, 0, -lo.y()}, {0, -1, 0, hi.y()}};
      for (int k = 0; k < 4; ++k) {
        glClipPlane(GL_CLIP_PLANE1 + k, tankSides[k]);
        glEnable(GL_CLIP_PLANE1 + k);
      }
      for (bool background : {true, false})
        for (const ColliderMesh& collider : colliders)
          if (collider.oneSided == background) drawCrossSection2d(collider);
      for (int k = 0; k < 4; ++k) glDisable(GL_CLIP_PLANE1 + k);
      if (tankEdges) drawOutline2d();
      return;
    }
    // Pulled a hair towards the camera, so that a plane lying on the ground is drawn over it.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(-1.0f, -1.0f);
    for (const ColliderMesh& collider : colliders) drawCollider(camera, collider);
    glDisable(GL_POLYGON_OFFSET_FILL);
  }

  // A collider in 3D: its albedo under sky and sun (Lambert and ambient, diffuseLight) at each vertex, with
  // the normal turned towards the camera; of a one-sided collider only the triangles that face the camera, as
  // the path tracer.
  void drawCollider(const PinholeCamera& camera, const ColliderMesh& collider) {
    const TriangleMesh& mesh = collider.mesh;
    const std::vector<Vec3> normals = vertexNormals(mesh);
    std::vector<Rgba> colours(mesh.positions.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      const Vec3 n =
          normals[i].dot(mesh.positions[i] - camera.position()) > 0 ? Vec3(-normals[i]) : normals[i];
      colours[i] = display(collider.albedo.cwiseProduct(diffuseLight(n)), look.exposure);
    }
    drawTriangles(mesh.positions, colours, trianglesFacing(collider, camera.position()));
  }

  // 2D: a collider's cross-section with the plane z = 0, flat in its albedo (as sRGB, like a diagram). A
  // closed solid holds the points (x, y, 0) from which a ray down -z crosses its surface an odd number of
  // times: its triangles clipped to z <= 0 invert the stencil where they cover, and a quad is then filled
  // where the stencil is odd; a container's solid is its outside, filled within the tank where the stencil is
  // even. A plane's solid is the half-plane behind it.
  void drawCrossSection2d(const ColliderMesh& collider) {
    const TriangleMesh& mesh = collider.mesh;
    if (mesh.triangles.empty()) return;
    Rgba colour = {0, 0, 0, 255};
    for (int k = 0; k < 3; ++k) colour[k] = encodeSrgb(std::clamp(collider.albedo[k], 0.0f, 1.0f));
    glDisable(GL_DEPTH_TEST);
    if (collider.plane) {
      Vec3 centre = Vec3::Zero();
      for (const Vec3& p : mesh.positions) centre += p;
      centre /= float(mesh.positions.size());
      const Vec3 n(collider.facing[0].x(), collider.facing[0].y(), 0.0f);
      if (n.norm() < 1e-6f) return;  // a plane facing the camera: no cross-section
      const Vec3 normal = n.normalized(), along(-normal.y(), normal.x(), 0.0f);
      const float far = 100.0f * size;
      centre.z() = 0;
      drawArrays(
          {centre + far * along, centre - far * along, centre - far * along - far * normal,
           centre + far * along, centre - far * along - far * normal, centre + far * along - far * normal},
          std::vector<Rgba>(6, colour));
      return;
    }
    glEnable(GL_STENCIL_TEST);
    glStencilMask(1);
    glClearStencil(0);
    glClear(GL_STENCIL_BUFFER_BIT);
    glStencilFunc(GL_ALWAYS, 0, 1);
    glStencilOp(GL_KEEP, GL_KEEP, GL_INVERT);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    const GLdouble belowPlane[4] = {0, 0, -1, 0};  // keeps z <= 0 (the modelview is the identity in 2D)
    glClipPlane(GL_CLIP_PLANE0, belowPlane);
    glEnable(GL_CLIP_PLANE0);
    glDisableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, mesh.positions.data());
    glDrawElements(GL_TRIANGLES, GLsizei(3 * mesh.triangles.size()), GL_UNSIGNED_INT, mesh.triangles.data());
    glEnableClientState(GL_COLOR_ARRAY);
    glDisable(GL_CLIP_PLANE0);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    const bool outside = !collider.plane && collider.oneSided;  // a container
    glStencilFunc(outside ? GL_EQUAL : GL_NOTEQUAL, 0, 1);
    // The tank for a container; for a solid, its box in x and y (the quad only has to cover it).
    Vec3 boxLo = lo, boxHi = hi;
    if (!outside) {
      boxLo = boxHi = mesh.positions[0];
      for (const Vec3& p : mesh.positions) {
        boxLo = boxLo.cwiseMin(p);
        boxHi = boxHi.cwiseMax(p);
      }
    }
    drawArrays({{boxLo.x(), boxLo.y(), 0},
                {boxHi.x(), boxLo.y(), 0},
                {boxHi.x(), boxHi.y(), 0},
                {boxLo.x(), boxLo.y(), 0},
                {boxHi.x(), boxHi.y(), 0},
                {boxLo.x(), boxHi.y(), 0}},
               std::vector<Rgba>(6, colour));
    glDisable(GL_STENCIL_TEST);
  }

  // The sky as horizontal bands behind everything, coloured by the camera ray through each band.
  void drawSky(const PinholeCamera& camera) {
    constexpr int bands = 48;
    std::vector<Vec3> positions;
    std::vector<Rgba> colours;
    for (int i = 0; i <= bands; ++i) {
      const float y = float(i) / bands;  // 0 at the top
      const Rgba c =
          display(skyRadiance(look, camera.rayThrough(0.5f * width, y * height).direction), look.exposure);
      positions.emplace_back(-1.0f, 1.0f - 2.0f * y, 0.0f);
      positions.emplace_back(1.0f, 1.0f - 2.0f * y, 0.0f);
      colours.push_back(c);
      colours.push_back(c);
    }
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glDepthMask(GL_FALSE);
    glDisable(GL_DEPTH_TEST);
    glVertexPointer(3, GL_FLOAT, 0, positions.data());
    glColorPointer(4, GL_UNSIGNED_BYTE, 0, colours.data());
    glDrawArrays(GL_TRIANGLE_STRIP, 0, GLsizei(positions.size()));
    glDepthMask(GL_TRUE);
    glEnable(GL_DEPTH_TEST);
  }

  // The checkerboard ground: squares within six tank sizes, a plain plane beyond (drawn first, without depth,
  // so the two never fight), both faded towards the horizon colour with distance like the path tracer's haze.
  void drawGround(const PinholeCamera& camera) {
    const Vec3 centre = 0.5f * (lo + hi);
    std::vector<Vec3> positions;
    std::vector<Rgba> colours;
    const auto shade = [&](const Vec3& p) {
      const float distance = (p - camera.position()).norm();
      const Vec3 lit = groundAlbedoAt(look, p, distance).cwiseProduct(diffuseLight(Vec3::UnitY()));
      const float r = distance / look.hazeDistance, haze = 1.0f - std::exp(-r * r);  // as the path tracer
      return display((1.0f - haze) * lit + haze * look.skyHorizon, look.exposure);
    };
    const auto quad = [&](float x0, float z0, float x1, float z1, const Rgba* flat) {
      const Vec3 corners[6] = {{x0, lo.y(), z0}, {x1, lo.y(), z0}, {x1, lo.y(), z1},
                               {x0, lo.y(), z0}, {x1, lo.y(), z1}, {x0, lo.y(), z1}};
      const Rgba c = flat ? *flat : shade(Vec3(0.5f * (x0 + x1), lo.y(), 0.5f * (z0 + z1)));
      for (const Vec3& p : corners) {
        positions.push_back(p);
        colours.push_back(flat ? shade(p) : c);
      }
    };
    const float far = 50.0f * size;
    const Rgba plain = {0, 0, 0, 255};
    quad(centre.x() - far, centre.z() - far, centre.x() + far, centre.z() + far, &plain);
    glDepthMask(GL_FALSE);
    drawArrays(positions, colours);
    glDepthMask(GL_TRUE);
    positions.clear();
    colours.clear();
    const float step = look.checkerSize;
    const int count = int(std::ceil(6.0f * size / step));
    const float x0 = lo.x() - count * step, z0 = lo.z() - count * step;
    for (int i = 0; i < 2 * count + 8; ++i)
      for (int j = 0; j < 2 * count + 8; ++j)
        quad(x0 + i * step, z0 + j * step, x0 + (i + 1) * step, z0 + (j + 1) * step, nullptr);
    drawArrays(positions, colours);
  }

  void drawTankEdges() {
    std::vector<Vec3> positions;
    for (const auto& [p0, p1] : surge::tankEdges(scene)) {
      positions.push_back(p0);
      positions.push_back(p1);
    }
    const std::vector<Rgba> colours(positions.size(), Rgba{30, 30, 34, 255});
    glLineWidth(float(std::max(2, height / 300)));
    glVertexPointer(3, GL_FLOAT, 0, positions.data());
    glColorPointer(4, GL_UNSIGNED_BYTE, 0, colours.data());
    glDrawArrays(GL_LINES, 0, GLsizei(positions.size()));
  }

  // 2D: a light tank interior on a pale backdrop, with a dark outline drawn over everything at the end.
  void drawTank2d() {
    const Rgba inside = display(Vec3::Constant(0.85f), 1.0f), backdrop = display(Vec3::Constant(0.6f), 1.0f);
    glClearColor(backdrop[0] / 255.0f, backdrop[1] / 255.0f, backdrop[2] / 255.0f, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    const float z = lo.z() - 10 * size;  // behind the fluid
    const std::vector<Vec3> positions = {{lo.x(), lo.y(), z}, {hi.x(), lo.y(), z}, {hi.x(), hi.y(), z},
                                         {lo.x(), lo.y(), z}, {hi.x(), hi.y(), z}, {lo.x(), hi.y(), z}};
    drawArrays(positions, std::vector<Rgba>(6, inside));
  }

  void drawOutline2d() {
    const float z = hi.z() + 10 * size;  // in front of the fluid
    std::vector<Vec3> positions;
    for (auto [p0, p1] : surge::tankEdges(scene)) {
      p0.z() = p1.z() = z;
      positions.push_back(p0);
      positions.push_back(p1);
    }
    const std::vector<Rgba> colours(positions.size(), Rgba{40, 40, 44, 255});
    glLineWidth(float(std::max(2, height / 250)));
    glVertexPointer(3, GL_FLOAT, 0, positions.data());
    glColorPointer(4, GL_UNSIGNED_BYTE, 0, colours.data());
    glDrawArrays(GL_LINES, 0, GLsizei(positions.size()));
  }

  static void drawArrays(const std::vector<Vec3>& positions, const std::vector<Rgba>& colours) {
    glVertexPointer(3, GL_FLOAT, 0, positions.data());
    glColorPointer(4, GL_UNSIGNED_BYTE, 0, colours.data());
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(positions.size()));
  }

  void drawTriangles(const std::vector<Vec3>& positions, const std::vector<Rgba>& colours,
                     const std::vector<std::array<uint32_t, 3>>& triangles) {
    if (triangles.empty()) return;
    glVertexPointer(3, GL_FLOAT, 0, positions.data());
    glColorPointer(4, GL_UNSIGNED_BYTE, 0, colours.data());
    glDrawElements(GL_TRIANGLES, GLsizei(3 * triangles.size()), GL_UNSIGNED_INT, triangles.data());
  }

  // Reads the GL buffer (bottom row first) into an image, averaging each 2x2 block.
  Image finish() {
    glFinish();
    Image image;
    image.width = width / kSupersample;
    image.height = height / kSupersample;
    image.rgb.resize(size_t(image.width) * image.height * 3);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int k = 0; k < 3; ++k) {
          int sum = 0;
          for (int dy = 0; dy < kSupersample; ++dy)
            for (int dx = 0; dx < kSupersample; ++dx) {
              const int gy = height - 1 - (y * kSupersample + dy), gx = x * kSupersample + dx;
              sum += buffer[4 * (size_t(gy) * width + gx) + k];
            }
          const int n = kSupersample * kSupersample;
          image.rgb[3 * (size_t(y) * image.width + x) + k] = uint8_t((sum + n / 2) / n);
        }
    return image;
  }
};

Rasterizer::Rasterizer(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.scene = scene;
  r.look = Shading::fromScene(scene);
  r.settings = resolvedRenderSettings(scene);
  r.width = kSupersample * r.settings.width;
  r.height = kSupersample * r.settings.height;
  r.lo = scene.domain.min.cast<float>();
  r.hi = scene.domain.max.cast<float>();
  r.size = std::max((r.hi - r.lo).maxCoeff(), 1e-3f);
  r.tankEdges = scene.render.tank != "none";
  // A stencil buffer for the 2D cross-sections of the colliders.
  r.context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (!r.context) throw RunError("OSMesa could not create a GL context");
  r.buffer.assign(size_t(r.width) * r.height * 4, 0);
  if (!OSMesaMakeCurrent(r.context, r.buffer.data(), GL_UNSIGNED_BYTE, r.width, r.height)) {
    OSMesaDestroyContext(r.context);
    throw RunError("OSMesa could not draw into a " + std::to_string(r.width) + "x" +
                   std::to_string(r.height) + " buffer");
  }
}

Rasterizer::~Rasterizer() {
  OSMesaDestroyContext(impl_->context);
}

Image Rasterizer::drawMesh(const TriangleMesh& water, const std::vector<ColliderMesh>& colliders,
                           const WhitewaterSpheres& whitewater, const std::vector<FluidMesh>& others) {
  Impl& r = *impl_;
  auto check = [](const TriangleMesh& mesh) {
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      for (uint32_t v : mesh.triangles[t])
        if (v >= mesh.positions.size())
          throw InputError(
              "water mesh", "triangle " + std::to_string(t),
              "names vertex " + std::to_string(v) + " of " + std::to_string(mesh.positions.size()));
  };
  check(water);
  for (const FluidMesh& other : others) check(other.mesh);
  OSMesaMakeCurrent(r.context, r.buffer.data(), GL_UNSIGNED_BYTE, r.width, r.height);
  const PinholeCamera camera(r.settings.camera, r.width, r.height);
  const bool flat = r.scene.dimensions == 2;
  r.begin(camera);
  // In 2D the water is one flat colour (the body seen through the slab), in 3D a Fresnel blend per vertex.
  auto drawLiquid = [&](const TriangleMesh& mesh, const Vec3& absorption) {
    const std::vector<Vec3> normals = vertexNormals(mesh);
    std::vector<Rgba> colours(mesh.positions.size());
    const Rgba body2d = display(r.waterColour(-Vec3::UnitZ(), Vec3::UnitZ(), absorption), r.look.exposure);
    parallelFor(0, mesh.positions.size(), [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i)
        colours[i] = flat ? body2d
                          : display(r.waterColour((mesh.positions[i] - camera.position()).normalized(),
                                                  normals[i], absorption),
                                    r.look.exposure);
    });
    r.drawTriangles(mesh.positions, colours, mesh.triangles);
  };
  drawLiquid(water, r.look.waterAbsorption);
  for (const FluidMesh& other : others) drawLiquid(other.mesh, other.absorption);
  if (!whitewater.empty()) {
    // Each particle a sphere (a disc in front of the 2D slab), diffuse in its albedo under sky and sun.
    const TriangleMesh sphere = unitSphere();
    const size_t nv = sphere.positions.size(), nt = sphere.triangles.size(), n = whitewater.spheres.size();
    std::vector<Vec3> positions(n * nv);
    std::vector<Rgba> sphereColours(n * nv);
    std::vector<std::array<uint32_t, 3>> triangles(n * nt);
    parallelFor(0, n, [&](size_t begin, size_t end) {
      for (size_t p = begin; p < end; ++p) {
        const Eigen::Vector4f& s = whitewater.spheres[p];
        Vec3 centre = s.head<3>();
        if (flat) centre.z() = float(r.scene.particle_spacing) * 4;  // in front of the slab
        // The 2D view shows a whole tank face-on: a disc is at least a spacing across, or it is a pixel.
        const float radius = flat ? std::max(s.w(), 0.5f * float(r.scene.particle_spacing)) : s.w();
        for (size_t v = 0; v < nv; ++v) {
          positions[p * nv + v] = centre + radius * sphere.positions[v];
          const Vec3 normal = flat ? Vec3::UnitZ() : Vec3(sphere.normals[v]);
          sphereColours[p * nv + v] =
              display(whitewater.albedo[p].cwiseProduct(r.diffuseLight(normal)), r.look.exposure);
        }
        for (size_t t = 0; t < nt; ++t)
          for (int k = 0; k < 3; ++k) triangles[p * nt + t][k] = uint32_t(p * nv + sphere.triangles[t][k]);
      }
    });
    r.drawTriangles(positions, sphereColours, triangles);
  }
  r.end(camera, colliders);
  return r.finish();
}

Image Rasterizer::drawParticles(const ParticleFrame& particles, const std::vector<ColliderMesh>& colliders) {
  Impl& r = *impl_;
  OSMesaMakeCurrent(r.context, r.buffer.data(), GL_UNSIGNED_BYTE, r.width, r.height);
  const PinholeCamera camera(r.settings.camera, r.width, r.height);
  const TriangleMesh sphere = unitSphere();
  const bool flat = r.scene.dimensions == 2;
  // In 2D the discs overlap (radius 0.8 spacing) in one flat water colour, so the fluid reads as one body;
  // in 3D they are spheres of the particle radius, shaded.
  const float radius = (flat ? 0.8f : 0.5f) * float(r.scene.particle_spacing);
  const Rgba body2d = display(r.waterColour(-Vec3::UnitZ(), Vec3::UnitZ()), r.look.exposure);
  // Every sphere is shaded alike: diffuse sun and sky on the water colour, seen along the camera's axis.
  std::vector<Rgba> sphereColours;
  for (const Vec3& n : sphere.normals) {
    const Vec3 base = r.scene.render.water_color.cast<float>();
    const Vec3 halfway = (r.look.sunDirection - camera.forward()).normalized();
    const float highlight = std::pow(std::max(n.dot(halfway), 0.0f), 60.0f);
    sphereColours.push_back(
        flat ? body2d
             : display(0.8f * base.cwiseProduct(r.diffuseLight(n)) + 0.5f * highlight * r.look.sunColor,
                       r.look.exposure));
  }
  const size_t nv = sphere.positions.size(), nt = sphere.triangles.size();
  std::vector<Vec3> positions(particles.size() * nv);
  std::vector<Rgba> colours(particles.size() * nv);
  std::vector<std::array<uint32_t, 3>> triangles(particles.size() * nt);
  parallelFor(0, particles.size(), [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p) {
      for (size_t v = 0; v < nv; ++v) {
        positions[p * nv + v] = particles.position[p] + radius * sphere.positions[v];
        colours[p * nv + v] = sphereColours[v];
      }
      for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) triangles[p * nt + t][k] = uint32_t(p * nv + sphere.triangles[t][k]);
    }
  });
  r.begin(camera);
  r.drawTriangles(positions, colours, triangles);
  r.end(camera, colliders);
  return r.finish();
}

}  // namespace surge
