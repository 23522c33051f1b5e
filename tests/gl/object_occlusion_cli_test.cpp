// Object-level occlusion through the CLI (under tests/gl: the GL-heavy CLI runs stay
// out of the ASan build's core|cli run, where one eval scene took over 9 minutes): `eval scene SCENE --json` (the JSON
// contract in tools/eval/eval_scene.cpp's head comment) and `render ... --objects M --object-occlusion O --verify
// --json` (tools/object_level_options.cpp). The methods: hardware occlusion queries stop-and-wait and
// batched, CHC (Bittner, Wimmer, Piringer, Purgathofer, "Coherent Hierarchical Culling: Hardware
// Occlusion Queries Made Useful") and CHC++ (Mattausch, Bittner, Wimmer, "CHC++: Coherent
// Hierarchical Culling Revisited"), the occlusion horizon (Downs, Möller, Séquin, "Occlusion Horizons
// for Driving through Urban Scenery") on data/scenes/city_small.json's box buildings, and cells and
// portals (Luebke & Georges, "Portals and Mirrors"; G. Zachmann, "Advanced Visibility Computations")
// on tests/data/scenes/two_rooms.json: two rooms joined by a door, the camera walking from the first
// through the door into the second; from the first room's frames the second room's BigGuy (behind
// the wall left of the door) and MonsterFrog (behind the wall right of it) are hidden.
// Every run is verified against the unculled render of each frame (strict: 0 false culls), except
// aggressive queries (--query-threshold), whose removed pixels are reported, not counted.
// Bad flags are one-line errors with exit status 2. Everything runs on llvmpipe at tiny sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_json_util.h"

using namespace patchcull::cli_test;
using nlohmann::json;

namespace {

std::string city_small() { return std::string(PATCHCULL_SOURCE_DIR) + "/data/scenes/city_small.json"; }
std::string two_rooms() { return std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/scenes/two_rooms.json"; }

// city_small.json: 20 characters (27,420 patches) and 5 box buildings.
constexpr std::size_t kCityObjects = 25, kCityCharacters = 20, kCityPatches = 27420;
// two_rooms.json: 2 BigGuys (1,450 patches each), a MonsterFrog (1,292) and a teapot (32); 14 boxes.
constexpr std::size_t kRoomsObjects = 18, kRoomsCharacters = 4, kRoomsPatches = 4224;
constexpr std::size_t kBigGuyPatches = 1450, kFrogPatches = 1292;

bool is_query_method(const std::string& m) {
    return m == "stop-and-wait" || m == "batched" || m == "chc" || m == "chc++";
}

// "chc+++hiz" -> "chc++"; "hiz" -> "hiz".
std::string without_hiz(const std::string& name) {
    const std::string suffix = "+hiz";
    return name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0
               ? name.substr(0, name.size() - suffix.size())
               : name;
}

struct SceneFacts {
    std::string name;
    std::size_t objects, characters, patches;
};

// Runs `eval scene`, checks the JSON contract (exact key sets of the top level, each method row and
// its ms), the rows' order (none first, then `methods` in the order given, or every method the
// scene allows when methods is empty), 0 false culls, and the counters' consistency with each
// method. Returns the rows.
std::vector<json> eval_scene(const std::string& scene, const SceneFacts& facts, const std::vector<std::string>& methods,
                             int frames, int tess) {
    std::string list;
    for (const std::string& m : methods) list += (list.empty() ? "" : ",") + m;
    const std::string args = "eval scene " + scene + " --size 128x72 --tess " + std::to_string(tess) + " --frames " +
                             std::to_string(frames) + (list.empty() ? "" : " --methods " + list) + " --json";
    const json j = run_json(args);
    const std::set<std::string> top{"scene", "scheme", "objects", "characters", "patches", "frames",          "size",
                                    "tess",  "batch",  "sigma",   "c1",         "methods", "visible_interval"};
    EXPECT_EQ(json_keys(j), top) << args;
    if (!j.contains("methods") || !j["methods"].is_array()) return {};
    EXPECT_EQ(j["scene"], facts.name);
    EXPECT_EQ(j["scheme"], "acc");
    EXPECT_EQ(j["objects"], facts.objects);
    EXPECT_EQ(j["characters"], facts.characters);
    EXPECT_EQ(j["patches"], facts.patches);
    EXPECT_EQ(j["frames"], frames);
    EXPECT_EQ(j["size"], json::array({128, 72}));
    EXPECT_EQ(j["tess"], tess);
    EXPECT_EQ(j["batch"], 16);  // the defaults
    EXPECT_EQ(j["visible_interval"], 1);
    EXPECT_NEAR(j["sigma"].get<double>(), 1.4, 1e-6);
    EXPECT_NEAR(j["c1"].get<double>(), 0.1, 1e-6);

    std::vector<std::string> expected_names{"none"};
    expected_names.insert(expected_names.end(), methods.begin(), methods.end());
    std::vector<json> rows(j["methods"].begin(), j["methods"].end());  // not const: returned by move
    std::vector<std::string> names;
    names.reserve(rows.size());
    for (const json& row : rows) names.push_back(row.value("name", "?"));
    if (!methods.empty()) {
        EXPECT_EQ(names, expected_names) << args;
    }

    const std::set<std::string> row_keys{"name",
                                         "object_method",
                                         "patch_hiz",
                                         "objects_culled",
                                         "objects_hidden",
                                         "patches_hidden",
                                         "patches_culled",
                                         "patches_object_culled",
                                         "patches_frustum_culled",
                                         "patches_occlusion_culled",
                                         "queries",
                                         "multiqueries",
                                         "multiqueries_passed",
                                         "proxy_boxes",
                                         "wait_frames",
                                         "waits",
                                         "ms",
                                         "frame_ratio",
                                         "false_culls"};
    const std::set<std::string> ms_keys{"object_cpu", "pass1", "hiz", "cull", "pass2", "frame"};
    const std::string what_prefix = args + ": ";
    for (const json& row : rows) {
        const std::string name = row.value("name", "?"), what = what_prefix + name;
        if (json_keys(row) != row_keys || json_keys(row["ms"]) != ms_keys) {
            ADD_FAILURE() << what << ": keys " << row.dump();
            continue;
        }
        bool numbers = true;
        for (const std::string& k : row_keys)
            if (k != "name" && k != "object_method" && k != "patch_hiz" && k != "ms")
                numbers = numbers && row[k].is_number() && row[k].get<double>() >= 0;
        for (const std::string& k : ms_keys)
            numbers = numbers && row["ms"][k].is_number() && row["ms"][k].get<double>() >= 0;
        if (!numbers) {
            ADD_FAILURE() << what << ": a count or time is not a number >= 0: " << row.dump();
            continue;
        }
        EXPECT_TRUE(row["wait_frames"].is_number_unsigned() && row["false_culls"].is_number_unsigned()) << what;
        EXPECT_EQ(row["false_culls"], 0) << what;
        EXPECT_LE(row["wait_frames"].get<int>(), frames) << what;
        EXPECT_GT(row["ms"]["frame"].get<double>(), 0) << what;
        const double ratio = row["frame_ratio"].get<double>();
        EXPECT_TRUE(std::isfinite(ratio) && ratio > 0) << what << ": " << ratio;

        const std::string object = without_hiz(name);
        const bool hiz = name == "hiz" || object != name;
        EXPECT_EQ(row["patch_hiz"], hiz) << what;
        EXPECT_EQ(row["object_method"], name == "none" || name == "hiz" ? "none" : object) << what;
        const double culled = row["patches_culled"].get<double>(),
                     by_objects = row["patches_object_culled"].get<double>();
        EXPECT_LE(culled, double(facts.patches)) << what;
        EXPECT_LE(by_objects, culled) << what;
        EXPECT_NEAR(
            culled,
            by_objects + row["patches_frustum_culled"].get<double>() + row["patches_occlusion_culled"].get<double>(),
            1e-6 * double(facts.patches))
            << what << ": every patch not drawn is culled once, by the object level or a patch pass";
        if (!hiz) {  // cull mode none: the patch passes cull nothing
            EXPECT_EQ(row["patches_frustum_culled"], 0) << what;
            EXPECT_EQ(row["patches_occlusion_culled"], 0) << what;
            EXPECT_EQ(row["ms"]["hiz"], 0) << what;
        }
        if (name == "none") {
            EXPECT_EQ(ratio, 1.0) << what << ": the ratios' denominator";
            EXPECT_EQ(culled, 0) << what;
        }
        // What the occlusion method itself hid is part of what the object level culled.
        EXPECT_LE(row["objects_hidden"].get<double>(), row["objects_culled"].get<double>() + 1e-9) << what;
        EXPECT_LE(row["patches_hidden"].get<double>(), by_objects + 1e-6) << what;
        if (name == "none" || name == "hiz") {
            EXPECT_EQ(row["objects_culled"], 0) << what;
            EXPECT_EQ(row["objects_hidden"], 0) << what;
            EXPECT_EQ(by_objects, 0) << what;
            EXPECT_EQ(row["ms"]["object_cpu"], 0) << what;
        }
        if (name == "hiz") {
            EXPECT_GT(row["patches_occlusion_culled"].get<double>(), 0) << what;
        }
        if (is_query_method(object)) {
            EXPECT_GT(row["queries"].get<double>(), 0) << what;
            EXPECT_GT(row["proxy_boxes"].get<double>(), 0) << what;
        } else {
            for (const char* k :
                 {"queries", "multiqueries", "multiqueries_passed", "proxy_boxes", "waits", "wait_frames"})
                EXPECT_EQ(row[k], 0) << what << ": " << k;
        }
        // Only CHC++ merges queries into multiqueries.
        if (object != "chc++") {
            EXPECT_EQ(row["multiqueries"], 0) << what;
        }
        EXPECT_LE(row["multiqueries_passed"].get<double>(), row["multiqueries"].get<double>()) << what;
    }
    return rows;
}

const json* row_named(const std::vector<json>& rows, const std::string& name) {
    for (const json& r : rows)
        if (r["name"] == name) return &r;
    ADD_FAILURE() << "no row " << name;
    return nullptr;
}

// What probing found, kept as cases: a mesh whose triangles sit on a box's corners and
// faces but leave half of two faces open (a doubled triangle makes up the area) is no box occluder;
// nor is a one-sided box whose front face is missing; and an eye within z_near of a wall (the near
// plane clips the wall away) must not let portal culling hide the next room.
TEST(ObjectOcclusionCli, ProbedFalseCullsStayFixed) {
    const std::string data = std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/scenes/";
    for (const char* scene : {"holebox.json", "openbox.json"})
        expect_one_line_error(
            run("render " + data + scene +
                " --size 160x90 --tess 2 --frames 2 --objects bvh --object-occlusion horizon --verify --json"),
            "has no box occluders");
    const json j = run_json(
        "render " + data +
        "near_wall.json --size 160x90 --tess 2 --frames 4 --objects bvh --object-occlusion portals --verify --json");
    EXPECT_EQ(j.value("false_culls", -1), 0);
    ASSERT_TRUE(j.contains("frames") && j["frames"].size() == 4u) << j.dump().substr(0, 500);
    // Frames 0-2: the eye 0.03..0.05 from the wall, within z_near 0.05: nothing culled by portals.
    for (int f = 0; f < 3; ++f) {
        const json& occ = j["frames"][f]["objects"]["occlusion"];
        EXPECT_EQ(occ["near_geometry"], true) << "frame " << f;
        EXPECT_EQ(occ["objects_culled"], 0) << "frame " << f;
    }
}

}  // namespace

// city_small: the query methods, CHC and CHC++ (with and without Hi-Z after them), the horizon.
TEST(ObjectOcclusionCli, EvalSceneCitySmallContract) {
    const std::vector<std::string> methods{"hiz",   "stop-and-wait", "batched", "chc",
                                           "chc++", "chc+hiz",       "horizon", "horizon+hiz"};
    const std::vector<json> rows =
        eval_scene(city_small(), {"city_small", kCityObjects, kCityCharacters, kCityPatches}, methods, 2, 1);
    for (const std::string& m : methods) {
        if (m == "hiz") continue;
        const json* r = row_named(rows, m);
        if (!r) continue;
        // The street's buildings hide characters of the other streets: every object method leaves
        // some out (objects_culled counts the frustum's too, patches_object_culled the patches).
        EXPECT_GT((*r)["objects_culled"].get<double>(), 0) << m;
        EXPECT_GT((*r)["objects_hidden"].get<double>(), 0) << m;
        EXPECT_GT((*r)["patches_object_culled"].get<double>(), 0) << m;
    }
    // CHC++ merges the hidden characters' queries into multiqueries.
    if (const json* r = row_named(rows, "chc++")) {
        EXPECT_GT((*r)["multiqueries"].get<double>(), 0);
    }
}

// two_rooms: every method the scene allows (the default list, portals and the horizon included),
// over the walk through the door.
TEST(ObjectOcclusionCli, EvalSceneTwoRoomsEveryMethod) {
    const std::vector<json> rows =
        eval_scene(two_rooms(), {"two_rooms", kRoomsObjects, kRoomsCharacters, kRoomsPatches}, {}, 4, 2);
    std::vector<std::string> names;
    names.reserve(rows.size());
    for (const json& r : rows) names.push_back(r["name"]);
    const std::vector<std::string> all{
        "none",    "hiz",   "stop-and-wait", "stop-and-wait+hiz", "batched",     "batched+hiz", "chc",
        "chc+hiz", "chc++", "chc+++hiz",     "horizon",           "horizon+hiz", "portals",     "portals+hiz"};
    EXPECT_EQ(names, all);
    for (const char* m : {"portals", "portals+hiz", "chc", "horizon"}) {
        const json* r = row_named(rows, m);
        if (!r) continue;
        EXPECT_GT((*r)["objects_culled"].get<double>(), 0) << m;
        EXPECT_GT((*r)["objects_hidden"].get<double>(), 0) << m;
        // Per frame mean: the hidden BigGuy and frog of the first frames.
        EXPECT_GT((*r)["patches_object_culled"].get<double>(), 0) << m;
    }
}

// The same as the CLI user sees it: render with each --object-occlusion method (and each --objects
// method beneath one of them), 0 false culls in every frame, the method echoed at the top and in
// each frame's objects.occlusion, whose counters add up.
TEST(ObjectOcclusionCli, RenderEveryOcclusionMethodHasNoFalseCulls) {
    struct Case {
        std::string scene, objects, occlusion, extra;
        std::size_t frames;
    };
    const std::string city = city_small() + " --tess 1", rooms = two_rooms() + " --tess 2";
    const std::vector<Case> cases{
        {city, "bvh", "none", "", 2},
        {city, "frustum", "stop-and-wait", "", 2},
        {city, "bvh", "batched", "--query-batch 4", 2},
        {city, "bvh+backface", "chc", "", 2},
        {city, "bvh", "chc++", "--query-batch 2 --tight-sigma 2", 2},
        {city, "bvh+backface", "horizon", "", 2},
        {rooms, "bvh", "portals", "", 4},
        {rooms, "frustum", "chc++", "", 4},
    };
    const std::set<std::string> query_keys{"method",      "objects", "frustum_culled", "occlusion_culled",
                                           "drawn",       "queries", "multiqueries",   "multiqueries_passed",
                                           "proxy_boxes", "waits",   "unqueryable",    "aggressive"};
    const std::set<std::string> scene_keys{"method",           "objects_tested",    "objects_culled", "patches_culled",
                                           "triangles_culled", "eye_in_cell",       "near_geometry",  "cells_reached",
                                           "portals_passed",   "occluders_inserted"};
    for (const Case& c : cases) {
        const std::string args = "render " + c.scene + " --size 128x72 --frames " + std::to_string(c.frames) +
                                 " --objects " + c.objects + " --object-occlusion " + c.occlusion + " " + c.extra +
                                 " --verify --json";
        const json j = run_json(args);
        if (!j.contains("frames")) continue;
        EXPECT_EQ(j["verified"], true) << args;
        EXPECT_EQ(j["false_culls"], 0) << args;
        EXPECT_EQ(j["object_occlusion"], c.occlusion) << args;
        EXPECT_EQ(j["objects_method"], c.objects) << args;
        ASSERT_EQ(j["frames"].size(), c.frames) << args;
        std::size_t occlusion_culled = 0, queries = 0;
        for (const json& frame : j["frames"]) {
            const std::string what = args + ", frame " + frame["frame"].dump();
            EXPECT_EQ(frame["false_culls"], 0) << what;
            ASSERT_TRUE(frame.contains("objects") && frame["objects"].contains("occlusion")) << what << frame.dump();
            const json& o = frame["objects"];
            EXPECT_EQ(o["false_culled_objects"], 0) << what;
            EXPECT_EQ(o["false_culled_triangles"], 0) << what;
            EXPECT_EQ(o["aggressive_pixels"], 0) << what << ": no --query-threshold";
            const json& occ = o["occlusion"];
            EXPECT_EQ(occ["method"], c.occlusion) << what;
            if (c.occlusion == "none") {
                EXPECT_EQ(json_keys(occ), std::set<std::string>{"method"}) << what;
            } else if (is_query_method(c.occlusion)) {
                ASSERT_EQ(json_keys(occ), query_keys) << what << ": " << occ.dump();
                EXPECT_EQ(occ["aggressive"], false) << what;
                // Every character is culled by the frustum, culled by a query, or drawn.
                const std::size_t characters = c.scene == city ? kCityCharacters : kRoomsCharacters;
                EXPECT_EQ(occ["objects"], characters) << what;
                EXPECT_EQ(occ["frustum_culled"].get<std::size_t>() + occ["occlusion_culled"].get<std::size_t>() +
                              occ["drawn"].get<std::size_t>(),
                          characters)
                    << what << ": " << occ.dump();
                if (c.occlusion != "chc++") {
                    EXPECT_EQ(occ["multiqueries"], 0) << what;
                }
                occlusion_culled += occ["occlusion_culled"].get<std::size_t>();
                queries += occ["queries"].get<std::size_t>();
            } else {
                ASSERT_EQ(json_keys(occ), scene_keys) << what << ": " << occ.dump();
                EXPECT_LE(occ["objects_culled"].get<std::size_t>(), occ["objects_tested"].get<std::size_t>()) << what;
                occlusion_culled += occ["objects_culled"].get<std::size_t>();
                if (c.occlusion == "horizon") {
                    EXPECT_GT(occ["occluders_inserted"].get<std::size_t>(), 0u) << what << ": the street's buildings";
                    EXPECT_EQ(occ["cells_reached"], 0) << what;
                } else {
                    EXPECT_EQ(occ["eye_in_cell"], true) << what << ": the walk stays inside the rooms";
                    EXPECT_GE(occ["cells_reached"].get<std::size_t>(), 1u) << what;
                    EXPECT_EQ(occ["occluders_inserted"], 0) << what;
                }
            }
        }
        if (c.occlusion == "none") continue;
        // Objects culled by occlusion itself, not only by the frustum before it.
        EXPECT_GT(occlusion_culled, 0u) << args;
        if (is_query_method(c.occlusion)) {
            EXPECT_GT(queries, 0u) << args;
        }
        if (c.occlusion == "portals") {
            // Frame 0, in the first room, looking through the door: the second room is reached
            // through it, and exactly its hidden BigGuy and frog are left out (the teapot shows
            // through the door; the guard stands in the first room).
            const json& occ = j["frames"][0]["objects"]["occlusion"];
            EXPECT_EQ(occ["cells_reached"], 2) << occ.dump();
            EXPECT_EQ(occ["portals_passed"], 1) << occ.dump();
            EXPECT_EQ(occ["patches_culled"], kBigGuyPatches + kFrogPatches) << occ.dump();
            EXPECT_GT(occ["triangles_culled"].get<std::size_t>(), 0u) << "the second room's walls out of sight";
        }
    }
}

// --query-threshold N (aggressive, approximate CHC): characters whose query passes no more than N
// samples are left out although visible. --verify reports their pixels as aggressive_pixels and does
// not count them as false culls: the run passes, and it culls more than the conservative run.
TEST(ObjectOcclusionCli, QueryThresholdReportsAggressivePixels) {
    const std::string base = "render " + city_small() + " --size 128x72 --tess 1 --frames 2 --objects bvh ";
    for (const char* method : {"chc", "stop-and-wait"}) {
        const json exact = run_json(base + "--object-occlusion " + method + " --verify --json");
        const json aggressive =
            run_json(base + "--object-occlusion " + method + " --query-threshold 400 --verify --json");
        if (!exact.contains("frames") || !aggressive.contains("frames")) continue;
        EXPECT_EQ(aggressive["false_culls"], 0) << method;
        EXPECT_EQ(aggressive["object_occlusion"], method);
        ASSERT_EQ(aggressive["frames"].size(), 2u);
        std::size_t pixels = 0, culled_exact = 0, culled_aggressive = 0;
        for (std::size_t f = 0; f < 2; ++f) {
            const json& a = aggressive["frames"][f]["objects"];
            const json& e = exact["frames"][f]["objects"];
            EXPECT_EQ(aggressive["frames"][f]["false_culls"], 0) << method << " frame " << f;
            EXPECT_EQ(a["false_culled_objects"], 0) << method << " frame " << f;
            EXPECT_EQ(a["occlusion"]["aggressive"], true) << method;
            EXPECT_EQ(e["occlusion"]["aggressive"], false) << method;
            EXPECT_EQ(e["aggressive_pixels"], 0) << method;
            pixels += a["aggressive_pixels"].get<std::size_t>();
            culled_exact += e["occlusion"]["occlusion_culled"].get<std::size_t>();
            culled_aggressive += a["occlusion"]["occlusion_culled"].get<std::size_t>();
        }
        // At 128x72 the far characters cover fewer than 400 samples: left out, yet visible.
        EXPECT_GT(pixels, 0u) << method;
        EXPECT_GT(culled_aggressive, culled_exact) << method;
    }
}

TEST(ObjectOcclusionCli, BadFlagsAreOneLineErrors) {
    const std::string e = "eval scene " + city_small() + " --size 32x18 --tess 1 --frames 1 --json ";
    expect_one_line_error(run(e + "--methods chc,bogus"), "--methods: 'bogus' is not a method");
    expect_one_line_error(run(e + "--methods chc,"), "--methods");
    expect_one_line_error(run(e + "--methods ''"), "--methods");
    expect_one_line_error(run(e + "--methods portals"), "--methods: 'portals' is not a method");  // no cells
    expect_one_line_error(run("eval scene teapot --size 32x18 --frames 1 --methods horizon --json"),
                          "--methods: 'horizon' is not a method");  // no box occluders
    expect_one_line_error(run("eval scene --json"), "SCENE");
    expect_one_line_error(run(e + "--frames 0"), "--frames");
    expect_one_line_error(run(e + "--batch 0"), "--batch");
    expect_one_line_error(run(e + "--sigma 0.5"), "--sigma");
    expect_one_line_error(run(e + "--max-tight-boxes 0"), "--max-tight-boxes");
    expect_one_line_error(run(e + "--c1 -1"), "--c1");
    expect_one_line_error(run(e + "--visible-interval 0"), "--visible-interval");

    const std::string r = "render " + city_small() + " --size 32x18 --tess 1 --frames 1 --json ";
    expect_one_line_error(run(r + "--objects bvh --object-occlusion bogus"), "--object-occlusion");
    expect_one_line_error(run(r + "--object-occlusion chc"), "--object-occlusion: needs --objects");
    expect_one_line_error(run(r + "--objects bvh --object-occlusion chc --query-batch 4"), "--query-batch");
    expect_one_line_error(run(r + "--objects bvh --object-occlusion stop-and-wait --query-batch 4"), "--query-batch");
    expect_one_line_error(run(r + "--objects bvh --object-occlusion chc --tight-sigma 2"), "--tight-sigma");
    expect_one_line_error(run(r + "--objects bvh --object-occlusion batched --tight-sigma 2"), "--tight-sigma");
    expect_one_line_error(run(r + "--objects bvh --query-threshold 5"), "--query-threshold");
    expect_one_line_error(run(r + "--objects bvh --object-occlusion horizon --query-threshold 5"), "--query-threshold");
    expect_one_line_error(run(r + "--objects bvh --object-occlusion chc --query-threshold -1"), "--query-threshold");
    expect_one_line_error(run(r + "--objects bvh --object-occlusion chc++ --query-batch 0"), "--query-batch");
    expect_one_line_error(run(r + "--objects bvh --object-occlusion chc++ --tight-sigma 0.5"), "--tight-sigma");
    expect_one_line_error(run(r + "--objects bvh --object-occlusion chc++ --cull auto"), "--object-occlusion");
    expect_one_line_error(run(r + "--objects bvh --object-occlusion portals"), "has no cells");
    expect_one_line_error(run("render teapot --size 32x18 --frames 1 --objects bvh --object-occlusion horizon --json"),
                          "has no box occluders");
}

// chc++'s rows name their object method whole; render names the flag when the scene lacks what
// the method needs.
TEST(ObjectOcclusionCli, EvalSceneNamesChcPlusPlusAndRenderNamesTheFlag) {
    const json j =
        run_json("eval scene " + two_rooms() + " --size 32x18 --tess 1 --frames 1 --methods chc++,chc+++hiz --json");
    ASSERT_TRUE(j.contains("methods") && j["methods"].size() == 3u) << j.dump();
    EXPECT_EQ(j["methods"][1]["object_method"].get<std::string>(), "chc++");
    EXPECT_EQ(j["methods"][2]["object_method"].get<std::string>(), "chc++");
    const std::string r = " --size 32x18 --tess 1 --frames 1 --objects bvh --json --object-occlusion ";
    expect_one_line_error(run("render " + city_small() + r + "portals"), "--object-occlusion");
    expect_one_line_error(run("render teapot" + r + "horizon"), "--object-occlusion");
}
