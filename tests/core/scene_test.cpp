#include "core/scene.h"

#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "core/errors.h"

namespace surge {
namespace {

const char* kValid = R"({
  "name": "tiny", "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [1, 1, 0.5]},
  "particle_spacing": 0.05,
  "fluids": [{"box": {"min": [0, 0, 0], "max": [0.4, 0.5, 0.5]}, "velocity": [1, 0, 0]}],
  "solver": {"substeps": 2},
  "output": {"fps": 24, "frames": 3}
})";

// Parses kValid with one key replaced (a JSON pointer such as "/solver/substeps") and expects an InputError
// whose one-line message names the file and `key`.
std::string errorFor(const std::string& pointer, const nlohmann::json& value, bool erase = false) {
  nlohmann::json scene = nlohmann::json::parse(kValid);
  if (erase)
    scene.erase(pointer.substr(1));
  else
    scene[nlohmann::json::json_pointer(pointer)] = value;
  try {
    parseScene(scene.dump(), "scene.json");
  } catch (const InputError& e) {
    EXPECT_EQ(e.exitStatus(), 2);
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind("scene.json: ", 0), 0u) << message;
    return message;
  }
  ADD_FAILURE() << "no error for " << pointer << " = " << value.dump();
  return "";
}

TEST(Scene, ParsesContractKeysAndResolvesDerivedDefaults) {
  const Scene scene = parseScene(kValid, "scene.json");
  EXPECT_EQ(scene.name, "tiny");
  EXPECT_EQ(scene.dimensions, 3);
  EXPECT_DOUBLE_EQ(scene.domain.max.z(), 0.5);
  ASSERT_EQ(scene.fluids.size(), 1u);
  EXPECT_DOUBLE_EQ(scene.fluids[0].velocity.x(), 1.0);
  EXPECT_EQ(scene.solver.substeps, 2);
  EXPECT_DOUBLE_EQ(scene.solver.rest_density, 1000);  // default
  EXPECT_DOUBLE_EQ(scene.output.fps, 24);
  EXPECT_DOUBLE_EQ(scene.solver.kernel_radius, 0.1);       // 2 x spacing
  EXPECT_DOUBLE_EQ(scene.surface.particle_radius, 0.05);   // spacing
  EXPECT_DOUBLE_EQ(scene.surface.voxel_size, 0.025);       // radius / 2
  // 8 x 10 x 10 lattice cells of 0.05 in the 0.4 x 0.5 x 0.5 box.
  EXPECT_EQ(scene.particleCount(), 800u);
}

TEST(Scene, OverridesApplyBeforeChecks) {
  const Scene scene = parseScene(kValid, "scene.json",
                                 {"solver.substeps=7", "fluids[0].velocity=[0,2,0]", "name=other"});
  EXPECT_EQ(scene.solver.substeps, 7);
  EXPECT_DOUBLE_EQ(scene.fluids[0].velocity.y(), 2.0);
  EXPECT_EQ(scene.name, "other");
  try {
    parseScene(kValid, "scene.json", {"solver.substeps=-1"});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--set: solver.substeps: -1 is out of range (>= 0, <= 100000)");
  }
  EXPECT_THROW(parseScene(kValid, "scene.json", {"solver.substep=3"}), InputError);
  EXPECT_THROW(parseScene(kValid, "scene.json", {"novalue"}), InputError);
  EXPECT_THROW(parseScene(kValid, "scene.json", {"fluids[3].velocity=[0,0,0]"}), InputError);
}

TEST(Scene, EveryBadInputIsOneLineNamingFileAndKey) {
  EXPECT_NE(errorFor("/solver/typo", 1).find("solver.typo: unknown key"), std::string::npos);
  EXPECT_NE(errorFor("/extra", 1).find("extra: unknown key"), std::string::npos);
  // Bytes that are not UTF-8 in a --set value (found by fuzz/fuzz_scene: the JSON library threw when the
  // message quoted them, and would again when scene.json is written). The file's own JSON refuses them itself.
  for (const char* assignment : {"solver.substeps=7+\xff\x8b", "name=ti\xff\xfeny"}) {
    try {
      parseScene(kValid, "scene.json", {assignment});
      ADD_FAILURE() << "accepted " << assignment;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--set: ", 0), 0u) << e.what();
    }
  }
  try {
    parseScene(kValid, "scene.json", {"name=ti\xff\xfeny"});
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("name: is not valid UTF-8 text"), std::string::npos) << e.what();
  }
  EXPECT_NE(errorFor("/solver/substeps", "four").find("solver.substeps: expected an integer"), std::string::npos);
  EXPECT_NE(errorFor("/solver/substeps", 2.5).find("solver.substeps: expected an integer"), std::string::npos);
  EXPECT_NE(errorFor("/particle_spacing", nullptr, true).find("particle_spacing: missing required key"),
            std::string::npos);
  EXPECT_NE(errorFor("/particle_spacing", 0).find("particle_spacing: 0 is out of range (> 0)"), std::string::npos);
  EXPECT_NE(errorFor("/particle_spacing", -0.1).find("particle_spacing"), std::string::npos);
  EXPECT_NE(errorFor("/fluids/0/box/max", {0.4, 0.5, 0.7}).find("fluids[0].box: lies outside the domain"),
            std::string::npos);
  EXPECT_NE(errorFor("/fluids/0/box/max", {0.01, 0.5, 0.5}).find("fluids: the fluid boxes hold no particles"),
            std::string::npos);
  EXPECT_NE(errorFor("/fluids", nlohmann::json::array()).find("fluids: the scene has no fluid"), std::string::npos);
  EXPECT_NE(errorFor("/domain/min", {0, 0}).find("domain.min: expected an array of 3 numbers"), std::string::npos);
  EXPECT_NE(errorFor("/dimensions", 4).find("dimensions: 4 is out of range"), std::string::npos);
  EXPECT_NE(errorFor("/domain/max", {1, 0, 0.5}).find("domain: min must be below max"), std::string::npos);
  EXPECT_NE(errorFor("/solver/kernel_radius", 0.04).find("solver.kernel_radius: must exceed"), std::string::npos);
  EXPECT_NE(errorFor("/surface/voxel_size", 1e-8).find("surface.voxel_size: the domain reaches more than 2^22"),
            std::string::npos);
}

// Emitters, sinks, open faces and shaped fluids: the keys issue 31 names, read, resolved and refused.
TEST(Scene, SourcesAndShapedFluidsAreReadAndCheckedByKey) {
  const nlohmann::json emitter = {{"position", {0.5, 0.9, 0.25}}, {"direction", {0, -2, 0}}, {"radius", 0.1},
                                  {"speed", 2}};
  nlohmann::json json = nlohmann::json::parse(kValid);
  json["fluids"] = nlohmann::json::array();
  json["emitters"] = {emitter};
  json["sinks"] = {{{"shape", "sphere"}, {"position", {0.5, 0.1, 0.25}}, {"radius", 0.1}}};
  json["domain"]["open"] = {"+x", "-z"};
  const Scene scene = parseScene(json.dump(), "scene.json");
  ASSERT_EQ(scene.emitters.size(), 1u);
  EXPECT_EQ(scene.emitters[0].name, "emitter0");
  EXPECT_EQ(scene.emitters[0].shape, "disc");
  EXPECT_DOUBLE_EQ(scene.emitters[0].stop, 0);  // never
  EXPECT_EQ(scene.sinks.at(0).name, "sink0");
  EXPECT_EQ(scene.open, (std::vector<std::string>{"+x", "-z"}));
  // scene.json reads back the same.
  const Scene again = parseScene(sceneToJson(scene), "scene.json");
  EXPECT_EQ(sceneToJson(again), sceneToJson(scene));

  auto error = [&](const std::string& pointer, const nlohmann::json& value) {
    nlohmann::json edited = json;
    edited[nlohmann::json::json_pointer(pointer)] = value;
    try {
      parseScene(edited.dump(), "scene.json");
    } catch (const InputError& e) {
      EXPECT_EQ(e.exitStatus(), 2);
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error("/emitters/0/direction", {0, 0, 0}), "scene.json: emitters[0].direction: must not be the zero vector");
  EXPECT_EQ(error("/emitters/0/position", {0.5, 1.2, 0.25}), "scene.json: emitters[0].position: lies outside the tank");
  EXPECT_EQ(error("/emitters/0/shape", "rectangle"),
            "scene.json: emitters[0].size: a rectangle needs its [width, height], both > 0");
  nlohmann::json late = emitter;
  late["start"] = 1.0;
  late["stop"] = 0.5;
  EXPECT_EQ(error("/emitters", nlohmann::json::array({late})), "scene.json: emitters[0].stop: must be after start (or 0: never)");
  EXPECT_EQ(error("/domain/open", {"+w"}), "scene.json: domain.open: '+w' is not one of: -x, +x, -y, +y, -z, +z");
  EXPECT_EQ(error("/domain/open", {"+x", "+x"}), "scene.json: domain.open: '+x' is named twice");
  EXPECT_EQ(error("/fluids", {{{"shape", "torus"}}}),
            "scene.json: fluids[0].shape: 'torus' is not one of: box, sphere, capsule, cylinder, mesh");
  EXPECT_EQ(error("/fluids", {{{"shape", "sphere"}, {"box", {{"min", {0, 0, 0}}, {"max", {1, 1, 0.5}}}}}}),
            "scene.json: fluids[0].box: give the fluid a box or a shape, not both");
  EXPECT_EQ(error("/fluids", {{{"shape", "sphere"}, {"position", {0.5, 0.5, 0.25}}, {"radius", 0.2}}}), "accepted");
  // emitters[i].fluid names a fluid; a block of neither box nor shape says what that fluid is, and only then.
  EXPECT_EQ(error("/emitters/0/fluid", "oil"),
            "scene.json: emitters[0].fluid: 'oil' is not the name of a fluid: the scene has no fluids blocks");
  nlohmann::json oil = json;
  oil["fluids"] = {{{"name", "water"}, {"box", {{"min", {0, 0, 0}}, {"max", {1, 0.2, 0.5}}}}},
                   {{"name", "oil"}, {"rest_density", 800}}};
  EXPECT_EQ(error("/fluids", oil["fluids"]), "scene.json: fluids[1].box: min must be below max on every axis (or give a shape)");
  oil["emitters"][0]["fluid"] = "oil";
  const Scene pouring = parseScene(oil.dump(), "scene.json");
  EXPECT_EQ(pouring.emittedFluid(0), 1u);
  EXPECT_EQ(pouring.particleCount(), size_t(20 * 4 * 10));  // the oil block holds none
  EXPECT_EQ(sceneToJson(parseScene(sceneToJson(pouring), "scene.json")), sceneToJson(pouring));
  oil["emitters"][0]["fluid"] = "honey";
  try {
    parseScene(oil.dump(), "scene.json");
    ADD_FAILURE() << "accepted honey";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "scene.json: emitters[0].fluid: 'honey' is not the name of a fluid: the scene has water, oil");
  }

  nlohmann::json flat = json;
  flat["dimensions"] = 2;
  flat["domain"] = {{"min", {0, 0}}, {"max", {1, 1}}, {"open", {"-z"}}};
  flat["emitters"] = {{{"position", {0.5, 0.9}}, {"direction", {0, -1}}}};
  flat["sinks"] = nlohmann::json::array();
  try {
    parseScene(flat.dump(), "flat.json");
    ADD_FAILURE() << "accepted -z in 2D";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "flat.json: domain.open: '-z' does not exist in 2D (faces -x, +x, -y, +y)");
  }
}

// A fluid's and a sink's files are found beside the scene file, as colliders' are, before the scene is checked
// (the simulator's defaults read a fluid mesh for its volume); scene.json holds them absolute.
TEST(Scene, FluidAndSinkFilesAreRelativeToTheSceneFile) {
  const fs::path folder = fs::path(testing::TempDir()) / "surge_scene_files";
  fs::create_directories(folder);
  nlohmann::json json = nlohmann::json::parse(kValid);
  json["fluids"] = {{{"shape", "mesh"}, {"file", "blob.obj"}, {"position", {0.5, 0.5, 0.25}}}};
  json["sinks"] = {{{"shape", "mesh"}, {"file", "drain.obj"}}};
  std::ofstream(folder / "scene.json") << json.dump();
  const Scene scene = loadScene(folder / "scene.json");
  EXPECT_EQ(scene.fluids.at(0).solid.file, fs::absolute(folder / "blob.obj").lexically_normal().string());
  EXPECT_EQ(scene.sinks.at(0).file, fs::absolute(folder / "drain.obj").lexically_normal().string());
}

// NaN, Infinity and -Infinity, as Python's json module writes them (JSON has neither), are named by their key,
// wherever they stand: a vector's element, a number, an integer, a string's place; inside a string they are text.
TEST(Scene, NonFiniteWordsAreNamedByTheirKey) {
  // kValid with each (from, to) replaced; the message of its InputError, or "accepted".
  auto messageFor = [](const std::vector<std::pair<std::string, std::string>>& edits) {
    std::string text = kValid;
    for (const auto& [from, to] : edits) {
      const size_t at = text.find(from);
      EXPECT_NE(at, std::string::npos) << from;
      if (at != std::string::npos) text.replace(at, from.size(), to);
    }
    try {
      parseScene(text, "scene.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(messageFor({{"\"particle_spacing\": 0.05", "\"particle_spacing\": NaN"}}),
            "scene.json: particle_spacing: is NaN; numbers must be finite");
  EXPECT_EQ(messageFor({{"\"max\": [1, 1, 0.5]", "\"max\": [1, Infinity, 0.5]"}}),
            "scene.json: domain.max: is Infinity; numbers must be finite");
  EXPECT_EQ(messageFor({{"\"dimensions\": 3", "\"dimensions\":-Infinity"}}),
            "scene.json: dimensions: is -Infinity; numbers must be finite");
  EXPECT_EQ(messageFor({{"\"name\": \"tiny\"", "\"name\": NaN"}}), "scene.json: name: is NaN; numbers must be finite");
  // As text, and as part of a longer word, they are left alone: the scene named "NaN" is read on to its spacing.
  EXPECT_EQ(messageFor({{"\"name\": \"tiny\"", "\"name\": \"NaN\""},
                        {"\"particle_spacing\": 0.05", "\"particle_spacing\": NaN"}}),
            "scene.json: particle_spacing: is NaN; numbers must be finite");
  EXPECT_NE(messageFor({{"\"dimensions\": 3", "\"dimensions\": NaNa"}}).find("invalid JSON"), std::string::npos);
}

TEST(Scene, InvalidJsonNamesTheByte) {
  try {
    parseScene("{\"name\": \"x\",, }", "bad.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("bad.json: byte 14: invalid JSON", 0), 0u) << e.what();
  }
}

TEST(Scene, TwoDimensionalVectorsHaveTwoComponents) {
  const char* scene2d = R"({"name": "flat", "dimensions": 2, "domain": {"min": [0, 0], "max": [2, 1]},
    "particle_spacing": 0.1, "fluids": [{"box": {"min": [0, 0], "max": [0.5, 0.5]}}], "gravity": [0, -9.81]})";
  const Scene scene = parseScene(scene2d, "flat.json");
  EXPECT_EQ(scene.particleCount(), 25u);
  EXPECT_DOUBLE_EQ(scene.domain.max.z(), 0.0);
  EXPECT_THROW(parseScene(scene2d, "flat.json", {"gravity=[0,-9.81,0]"}), InputError);
}

TEST(Scene, ResolvedSceneRoundTripsThroughJson) {
  const Scene scene = parseScene(kValid, "scene.json", {"solver.substeps=3"});
  const std::string text = sceneToJson(scene);
  const Scene again = parseScene(text, "resolved.json");
  EXPECT_EQ(sceneToJson(again), text);
  EXPECT_EQ(again.solver.substeps, 3);
}

}  // namespace
}  // namespace surge
