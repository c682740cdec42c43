// 3D loop closure (mapping/loop_closure3d.hpp): on a simulated loop around the campus block it
// must reduce the error against the simulator's truth, verification must reject a wrong candidate,
// a street of identical buildings must not produce a wrong edge, bad input must be rejected, and
// `odometry --loop-closure` must write its files, the same on loop closure's own thread as inline.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/mapping/loop_closure3d.hpp"
#include "scanmatch/mapping/loop_verification3d.hpp"
#include "scanmatch/registration/methods.hpp"
#include "scanmatch/registration/prepared_cloud.hpp"
#include "scanmatch/run/odometry_run.hpp"
#include "scanmatch/sim/scene.hpp"
#include "scanmatch/sim/sensor.hpp"
#include "scanmatch/sim/simulator.hpp"
#include "test_helpers.hpp"

namespace scanmatch {
namespace {

// The frames of a simulated preset without motion distortion (as deskewed odometry gives them),
// downsampled as the odometry would, every `step`-th frame.
struct SimulatedFrames {
  std::vector<PointCloud> clouds;
  std::vector<Pose> truth;
};

SimulatedFrames simulate(sim::SimOptions options, std::size_t step) {
  options.motion_distortion = false;
  const sim::Simulator simulator(options);
  SimulatedFrames out;
  for (std::size_t i = 0; i < simulator.size(); i += step) {
    out.clouds.push_back(voxel_downsample(simulator.frame(i), 0.25));
    out.truth.push_back(simulator.pose(i));
  }
  return out;
}

// An odometry that drifts in a known way: each true step 0.2 % too long (a loop cannot show a scale
// error: the scaled loop closes too), turned by a small yaw and pitch bias per metre.
std::vector<Pose> drifting_odometry(const std::vector<Pose>& truth, double yaw_per_m,
                                    double pitch_per_m) {
  std::vector<Pose> odometry = {Pose::Identity()};
  for (std::size_t i = 1; i < truth.size(); ++i) {
    Pose step = truth[i - 1].inverse() * truth[i];
    const double length = step.translation().norm();
    step.translation() *= 1.002;
    odometry.push_back(odometry.back() * step *
                       from_xyz_rpy(0, 0, 0, 0, pitch_per_m * length, yaw_per_m * length));
  }
  return odometry;
}

// Every accepted loop's relative pose against the truth's.
void expect_loops_agree_with_truth(const LoopClosure3D& loops, const std::vector<Pose>& truth,
                                   double max_translation, double max_angle) {
  for (const Loop3D& l : loops.loops()) {
    if (l.outlier) continue;
    const Pose expected = truth[l.from_frame].inverse() * truth[l.to_frame];
    const Pose error = expected.inverse() * l.relative;
    EXPECT_LT(error.translation().norm(), max_translation) << l.from_frame << " -> " << l.to_frame;
    EXPECT_LT(rotation_angle(error), max_angle) << l.from_frame << " -> " << l.to_frame;
  }
}

TEST(LoopClosure3D, ClosesTheCampusLoop) {
  // dynamic-outdoor-fast drives 0.44 m per frame; 1000 frames go once around the campus block
  // (~390 m) and 50 m on. Every second frame is fed, with a drifting odometry.
  sim::SimOptions options;
  options.preset = "dynamic-outdoor-fast";
  options.frames = scanmatch::testing::sanitized() ? 400 : 1000;
  const SimulatedFrames frames = simulate(options, 2);
  const std::vector<Pose> odometry =
      drifting_odometry(frames.truth, 0.01 * M_PI / 180, 0.001 * M_PI / 180);
  LoopClosure3D loops;
  for (std::size_t i = 0; i < frames.clouds.size(); ++i)
    loops.add_frame(frames.clouds[i], odometry[i]);
  loops.finish();
  const std::vector<Pose> optimized = loops.poses();
  ASSERT_EQ(optimized.size(), odometry.size());
  const AteResult before = compute_ate(frames.truth, odometry);
  const AteResult after = compute_ate(frames.truth, optimized);
  const LoopClosure3DCounts& c = loops.counts();
  std::printf(
      "campus loop, %zu frames: ATE odometry %.3f m, loop-closed %.3f m; %zu keyframes, %zu "
      "candidates, %zu verified, %zu rejected by verification, %zu by the estimate, %zu outliers, "
      "%.2f ms per frame\n",
      optimized.size(), before.rmse, after.rmse, c.keyframes, c.candidates, c.verified,
      c.rejected_by_verification, c.rejected_by_estimate, c.outliers,
      c.total_ms / static_cast<double>(optimized.size()));
  if (scanmatch::testing::sanitized()) return;
  EXPECT_GT(before.rmse, 1.0);
  EXPECT_GT(c.verified, 0u);
  EXPECT_LT(after.rmse, before.rmse / 3.0);
  expect_loops_agree_with_truth(loops, frames.truth, 0.3, 2.0 * M_PI / 180);
}

TEST(LoopClosure3D, VerificationRejectsAWrongCandidate) {
  sim::SimOptions options;
  options.preset = "dynamic-outdoor-fast";
  options.frames = 200;
  const SimulatedFrames frames = simulate(options, 1);
  const LoopVerification3DOptions verification;
  // A frame against itself from a guess 1 m and 10 deg off: the same place.
  const PointCloud& here = frames.clouds[20];
  const LoopVerification3D same =
      verify_loop_3d(here, here, from_xyz_rpy(1.0, -0.5, 0.1, 0, 0, 0.17), verification);
  EXPECT_TRUE(same.accepted) << same.overlap << " " << same.error << " " << same.constraint;
  EXPECT_FALSE(same.prechecked_out);
  EXPECT_LT(same.transform.translation().norm(), 0.05);
  // The same frame 300 m away (beyond its range): the cheap pre-check rejects it before the fine
  // stage.
  PointCloud far_away = here;
  for (Point& p : far_away.points) p.x() += 300.0f;
  const LoopVerification3D far = verify_loop_3d(far_away, here, Pose::Identity(), verification);
  EXPECT_FALSE(far.accepted);
  EXPECT_TRUE(far.prechecked_out);
  // Frames 50 m apart on the same street: the descriptor's best yaw and the identity both start
  // from the wrong place, and nothing may verify.
  const PointCloud& there = frames.clouds[140];
  const PlaceMatch match = compare(make_place_descriptor(there), make_place_descriptor(here));
  for (const Pose& guess : {Pose(Pose::Identity()), from_xyz_rpy(0, 0, 0, 0, 0, match.yaw)}) {
    const LoopVerification3D v = verify_loop_3d(there, here, guess, verification);
    EXPECT_FALSE(v.accepted) << v.overlap << " " << v.error << " " << v.constraint;
  }
}

// Registering and verifying with prepared submaps (kept structures, loop closure's cache) gives
// the generic path's results, bit for bit; an estimate's expectation only rejects early what it
// rules out.
TEST(LoopClosure3D, PreparedSubmapsRegisterAndVerifyAsTheGenericPath) {
  sim::SimOptions options;
  options.preset = "dynamic-outdoor-fast";
  options.frames = 30;
  const SimulatedFrames frames = simulate(options, 1);
  const PointCloud &here = frames.clouds[10], &near = frames.clouds[14], &far = frames.clouds[29];
  PreparedCloud prepared_here(here), prepared_near(near), prepared_far(far);
  // Each method twice: the second registration reads what the first built. point-to-plane is not
  // prepared: register_prepared runs register_clouds for it.
  const Pose guess = from_xyz_rpy(0.3, -0.2, 0.05, 0, 0, 0.05);
  for (const std::string method : {"ndt", "gicp", "point-to-plane"}) {
    RegistrationOptions o;
    o.method = method;
    o.voxel_resolution = 2.0;
    const RegistrationResult generic = register_clouds(near, here, o, guess);
    for (int round = 0; round < 2; ++round) {
      const RegistrationResult prepared = register_prepared(prepared_near, prepared_here, o, guess);
      EXPECT_EQ(prepared.transform.matrix(), generic.transform.matrix()) << method << round;
      EXPECT_EQ(prepared.iterations, generic.iterations) << method << round;
      EXPECT_EQ(prepared.information, generic.information) << method << round;
    }
  }
  EXPECT_THROW(register_prepared(
                   prepared_near, prepared_here,
                   [] {
                     RegistrationOptions o;
                     o.method = "no-such-method";
                     return o;
                   }(),
                   guess),
               Error);
  // Verification: a keyframe against two others in turn, then again, as loop closure does.
  const LoopVerification3DOptions verification;
  const auto expect_same = [](const LoopVerification3D& a, const LoopVerification3D& b) {
    EXPECT_EQ(a.accepted, b.accepted);
    EXPECT_EQ(a.prechecked_out, b.prechecked_out);
    EXPECT_EQ(a.transform.matrix(), b.transform.matrix());
    EXPECT_EQ(a.overlap, b.overlap);
    EXPECT_EQ(a.error, b.error);
    EXPECT_EQ(a.constraint, b.constraint);
    EXPECT_EQ(a.hessian, b.hessian);
  };
  const LoopVerification3D generic_near = verify_loop_3d(here, near, guess, verification);
  const LoopVerification3D generic_far = verify_loop_3d(here, far, guess, verification);
  EXPECT_TRUE(generic_near.accepted);  // so that the comparison covers every stage
  const std::size_t unprepared = prepared_far.memory_bytes();
  for (int round = 0; round < 2; ++round) {
    expect_same(verify_loop_3d(prepared_here, prepared_near, guess, verification), generic_near);
    expect_same(verify_loop_3d(prepared_here, prepared_far, guess, verification), generic_far);
  }
  EXPECT_GT(prepared_far.memory_bytes(), unprepared);  // it kept what was built
  // An estimate that expects the loop where it is changes nothing; one 10 m away rejects it
  // before the fine stage.
  const Eigen::Vector3d found = generic_near.transform.translation();
  expect_same(verify_loop_3d(prepared_here, prepared_near, guess, verification,
                             LoopExpectation{found + Eigen::Vector3d(0.5, 0, 0), 1.0}),
              generic_near);
  const LoopVerification3D elsewhere =
      verify_loop_3d(prepared_here, prepared_near, guess, verification,
                     LoopExpectation{found + Eigen::Vector3d(10, 0, 0), 1.0});
  EXPECT_FALSE(elsewhere.accepted);
  EXPECT_TRUE(elsewhere.prechecked_out && elsewhere.beyond_expectation);
}

// verification_memory_mb bounds what loop closure keeps of its submaps' structures, and only the
// time changes with it.
TEST(LoopClosure3D, VerificationMemoryStaysWithinItsBudgetWithTheSameLoops) {
  // Out along a street and back: the way back revisits every keyframe of the way out.
  sim::SimOptions options;
  options.preset = "dynamic-outdoor-fast";
  options.frames = 50;
  const SimulatedFrames frames = simulate(options, 1);
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < frames.clouds.size(); ++i) order.push_back(i);
  for (std::size_t i = frames.clouds.size(); i-- > 0;) order.push_back(i);
  const auto run = [&](double memory_mb) {
    LoopClosure3DOptions o;
    o.skip_recent = 8;
    o.verification_memory_mb = memory_mb;
    auto loops = std::make_unique<LoopClosure3D>(o);
    for (const std::size_t i : order) {
      loops->add_frame(frames.clouds[i], frames.truth[i]);
      EXPECT_LE(static_cast<double>(loops->verification_memory_bytes()), memory_mb * 1024 * 1024);
    }
    loops->finish();
    return loops;
  };
  const auto unbounded = run(1000.0), small = run(2.5), none = run(0.0);
  ASSERT_GT(unbounded->loops().size(), 2u);
  for (const LoopClosure3D* other : {small.get(), none.get()}) {
    ASSERT_EQ(other->loops().size(), unbounded->loops().size());
    for (std::size_t i = 0; i < unbounded->loops().size(); ++i) {
      EXPECT_EQ(other->loops()[i].from_frame, unbounded->loops()[i].from_frame);
      EXPECT_EQ(other->loops()[i].relative.matrix(), unbounded->loops()[i].relative.matrix());
    }
    EXPECT_EQ(other->counts().candidates, unbounded->counts().candidates);
  }
  // Kept submaps are verified again without being rebuilt (each loop's two submaps were
  // prepared only once: here the way back's keyframes verify against the way out's, which had
  // verified nothing); a smaller budget rebuilds some, none keeps none from one keyframe to the
  // next.
  EXPECT_LE(unbounded->counts().submaps_prepared, unbounded->counts().candidates);
  EXPECT_GT(unbounded->verification_memory_bytes(), 2u * 1024u * 1024u);
  EXPECT_GE(small->counts().submaps_prepared, unbounded->counts().submaps_prepared);
  EXPECT_GT(none->counts().submaps_prepared, unbounded->counts().submaps_prepared);
  EXPECT_GE(none->counts().submaps_prepared, small->counts().submaps_prepared);
  EXPECT_EQ(none->verification_memory_bytes(), 0u);
}

TEST(LoopClosure3D, BadInputIsRejectedNotFatal) {
  sim::SimOptions options;
  options.preset = "dynamic-outdoor-fast";
  options.frames = 3;
  const SimulatedFrames frames = simulate(options, 1);
  const LoopVerification3DOptions verification;
  PointCloud broken = frames.clouds[0];
  broken.points[5].x() = std::nanf("");
  EXPECT_FALSE(
      verify_loop_3d(PointCloud{}, frames.clouds[0], Pose::Identity(), verification).accepted);
  EXPECT_FALSE(verify_loop_3d(broken, frames.clouds[0], Pose::Identity(), verification).accepted);
  Pose not_finite = Pose::Identity();
  not_finite.translation().x() = std::nan("");
  EXPECT_FALSE(
      verify_loop_3d(frames.clouds[0], frames.clouds[0], not_finite, verification).accepted);
  // The sequence: empty frames, NaN points, far-away points and a NaN pose all go in.
  LoopClosure3D loops;
  PointCloud far = frames.clouds[1];
  far.points[0] = Point(1e12f, 0.0f, 0.0f);
  EXPECT_TRUE(loops.add_frame(PointCloud{}, Pose::Identity()));
  loops.add_frame(broken, from_xyz_rpy(0.5, 0, 0, 0, 0, 0));
  loops.add_frame(far, from_xyz_rpy(1.0, 0, 0, 0, 0, 0));
  loops.add_frame(frames.clouds[2], not_finite);
  loops.finish();
  ASSERT_EQ(loops.frames(), 4u);
  for (const Pose& p : loops.poses()) EXPECT_TRUE(p.matrix().allFinite());
  EXPECT_THROW(LoopClosure3D([] {
                 LoopClosure3DOptions o;
                 o.verification.fine_method = "no-such-method";
                 return o;
               }()),
               Error);
  EXPECT_THROW(LoopClosure3D([] {
                 LoopClosure3DOptions o;
                 o.submap_voxel = 0.0;
                 return o;
               }()),
               Error);
}

// A street of identical buildings, lamp posts and parked cars every 20 m on both sides: every
// place looks like the ones 20 m away, to the descriptor and to the registration alike.
sim::Scene repeated_street() {
  sim::Scene scene;
  sim::Ground ground;
  ground.half_extent = 250;
  ground.cell = 5;
  scene.set_ground(ground);
  for (double x = -20; x <= 120; x += 20) {
    for (double side : {-1.0, 1.0}) {
      scene.add(sim::Box{{x, side * 16, 5}, {12, 8, 10}, 0.0, 0.55f});
      scene.add(sim::Box{{x + 3, side * 11.5, 1.5}, {4, 1, 3}, 0.0, 0.5f});       // entrance
      scene.add(sim::Cylinder{{x + 8, side * 6}, 0.1, 0, 6, 0.6f});               // lamp post
      scene.add(sim::Box{{x - 5, side * 4.5, 0.7}, {4.4, 1.8, 1.4}, 0.0, 0.8f});  // parked car
    }
  }
  scene.commit();
  return scene;
}

// The sensor's frame at `pose` (scene frame) without noise or motion: a rendering of the scene.
PointCloud render(const sim::Scene& scene, const sim::SensorModel& sensor, std::size_t index,
                  const Pose& pose) {
  sim::RayPattern pattern;
  sim::generate_pattern(sensor, index, pattern);
  PointCloud cloud;
  for (const Eigen::Vector3f& d : pattern.directions) {
    const Eigen::Vector3d dir = pose.linear() * d.cast<double>();
    const sim::RayHit hit =
        scene.raycast(pose.translation(), dir, sensor.min_range, sensor.max_range);
    if (hit.hit) cloud.points.push_back(d * static_cast<float>(hit.range));
  }
  return voxel_downsample(cloud, 0.25);
}

TEST(LoopClosure3D, RepeatedStructureGivesNoWrongEdge) {
  // Down the street 70 m on the right lane, a U-turn, and back on the other lane: every place on
  // the way back is revisited, and aliases of it lie every 20 m. The odometry drifts a few metres
  // (less than the 20 m spacing: loop closure cannot know which copy it is at beyond that).
  if (scanmatch::testing::sanitized()) GTEST_SKIP() << "150 ray-cast frames: too slow sanitized";
  std::vector<Pose> truth_scene;
  for (double x = 0; x <= 70; x += 1.0) truth_scene.push_back(from_xyz_rpy(x, -2, 0.5, 0, 0, 0));
  for (double a = 0.25; a < M_PI; a += 0.25)
    truth_scene.push_back(from_xyz_rpy(70 + 2 * std::sin(a), -2 * std::cos(a), 0.5, 0, 0, a));
  for (double x = 70; x >= 0; x -= 1.0) truth_scene.push_back(from_xyz_rpy(x, 2, 0.5, 0, 0, M_PI));
  const sim::Scene scene = repeated_street();
  const sim::SensorModel& sensor = sim::sensor_model("mid360");
  std::vector<Pose> truth;
  LoopClosure3D loops;
  std::vector<Pose> odometry;
  for (std::size_t i = 0; i < truth_scene.size(); ++i)
    truth.push_back(truth_scene.front().inverse() * truth_scene[i]);
  odometry = drifting_odometry(truth, 0.01 * M_PI / 180, 0.0);
  for (std::size_t i = 0; i < truth.size(); ++i)
    loops.add_frame(render(scene, sensor, i, truth_scene[i]), odometry[i]);
  loops.finish();
  const LoopClosure3DCounts& c = loops.counts();
  const AteResult before = compute_ate(truth, odometry);
  const AteResult after = compute_ate(truth, loops.poses());
  std::printf(
      "repeated street, %zu frames: ATE odometry %.3f m, loop-closed %.3f m; %zu candidates, %zu "
      "verified, %zu rejected by verification, %zu by the estimate, %zu outliers\n",
      truth.size(), before.rmse, after.rmse, c.candidates, c.verified, c.rejected_by_verification,
      c.rejected_by_estimate, c.outliers);
  EXPECT_GT(c.candidates, 0u);
  expect_loops_agree_with_truth(loops, truth, 0.3, 2.0 * M_PI / 180);
  // The premise: verification alone accepts a look-alike 20 m away (the keyframes at x = 20 and
  // x = 40 on the way out, from the identity), so it is the estimate that keeps it out.
  const LoopVerification3D alias =
      verify_loop_3d(loops.submap(loops.keyframe_of(40)), loops.submap(loops.keyframe_of(20)),
                     Pose::Identity(), LoopVerification3DOptions{});
  EXPECT_TRUE(alias.accepted) << alias.overlap << " " << alias.error << " " << alias.constraint;
  EXPECT_LT(alias.transform.translation().norm(), 1.0);
  EXPECT_LE(after.rmse, before.rmse * 1.05);
}

// A small loop through the campus: 30 m down the road at 4 m/s, a U-turn at 1 m/s (0.7 rad/s),
// and back to the start.
Trajectory short_campus_loop() {
  Trajectory t;
  const double speed = 4.0;  // m/s
  double time = 0.0;
  const auto add = [&](double x, double y, double yaw, double step) {
    time += step / speed;
    t.timestamps.push_back(time);
    t.poses.push_back(from_xyz_rpy(x, y, 0, 0, 0, yaw));
  };
  for (double x = 0; x <= 30; x += 0.2) add(x, 0, 0, 0.2);
  for (double a = 0.1; a < M_PI; a += 0.1)
    add(30 + 1.5 * std::sin(a), 1.5 - 1.5 * std::cos(a), a, 0.6);
  for (double x = 30; x >= -2; x -= 0.2) add(x, 3, M_PI, 0.2);
  return t;
}

std::unique_ptr<SequenceSource> short_campus_loop_sequence() {
  sim::SimOptions simulation;
  simulation.preset = "dynamic-outdoor-fast";
  simulation.trajectory = short_campus_loop();
  simulation.frames = 100000;  // the whole trajectory
  return sim::simulated_sequence(simulation);
}

// `run` with loop closure and the map, into `out_dir`.
RunSummary run_with_loop_closure(SequenceSource& source, const std::string& out_dir,
                                 RunOptions run = {}) {
  run.out_dir = out_dir;
  run.write_map = true;
  run.loop_closure = true;
  run.quiet = true;
  return run_odometry(source, OdometryConfig{}, run);
}

TEST(LoopClosure3D, RunOdometryWritesTheLoopClosedRun) {
  scanmatch::testing::TempDir dir;
  const auto source = short_campus_loop_sequence();
  const RunSummary summary = run_with_loop_closure(*source, dir.file("run"));
  for (const char* name :
       {"poses.txt", "poses_tum.txt", "poses_optimized.txt", "poses_optimized_tum.txt",
        "loops.json", "summary.json", "config.json", "map.pcd", "map_odometry.pcd"})
    EXPECT_TRUE(std::filesystem::exists(dir.file(std::string("run/") + name))) << name;
  const Trajectory optimized = read_trajectory(dir.file("run/poses_optimized_tum.txt"));
  EXPECT_EQ(optimized.size(), summary.frames);
  const auto summary_json = nlohmann::json::parse(std::ifstream(dir.file("run/summary.json")));
  ASSERT_TRUE(summary_json.contains("loop_closure"));
  ASSERT_TRUE(summary_json.contains("ate") && summary_json.contains("ate_odometry"));
  const auto loops = nlohmann::json::parse(std::ifstream(dir.file("run/loops.json")));
  ASSERT_TRUE(loops.is_array());
  EXPECT_EQ(summary_json["loop_closure"]["accepted"].get<std::size_t>(), loops.size());
  EXPECT_GT(loops.size(), 0u);
  std::printf("short campus loop, %zu frames: ATE odometry %.3f m, loop-closed %.3f m, %zu loops\n",
              summary.frames, summary_json["ate_odometry"]["rmse_m"].get<double>(),
              summary_json["ate"]["rmse_m"].get<double>(), loops.size());
  // Every written loop agrees with the simulator's truth, up to the odometry's local error: a
  // submap is built from the odometry's poses, so a keyframe whose pose the odometry got locally
  // wrong (3 deg of roll out of the U-turn here) measures the loop in that wrong frame.
  for (const auto& l : loops) {
    const auto from = l.at("from").get<std::size_t>(), to = l.at("to").get<std::size_t>();
    ASSERT_LT(from, to);
    ASSERT_LT(to, summary.ground_truth.size());
    const Pose truth = summary.ground_truth[from].inverse() * summary.ground_truth[to];
    const Pose written = from_kitti_row(l.at("kitti_row").get<std::array<double, 12>>());
    const Pose error = truth.inverse() * written;
    EXPECT_LT(error.translation().norm(), 0.5) << from << " -> " << to << ": " << l.dump();
    EXPECT_LT(rotation_angle(error), 5.0 * M_PI / 180) << from << " -> " << to << ": " << l.dump();
  }
  EXPECT_LE(summary_json["ate"]["rmse_m"].get<double>(),
            summary_json["ate_odometry"]["rmse_m"].get<double>() * 1.05);
  const auto config = nlohmann::json::parse(std::ifstream(dir.file("run/config.json")));
  EXPECT_TRUE(config.at("loop_closure").get<bool>());
  EXPECT_TRUE(config.at("loop_closure_thread").get<bool>());
  EXPECT_TRUE(summary_json["loop_closure"]["thread"].get<bool>());
  EXPECT_GT(summary_json["wall_ms_per_frame"].get<double>(), 0.0);
}

// Loop closure sees the same frames in the same order on its thread as inline: the same loops,
// poses and map, byte for byte.
void expect_same_loop_closed_runs(const std::string& a, const std::string& b) {
  for (const char* name : {"loops.json", "poses_optimized.txt", "poses_optimized_tum.txt",
                           "map.pcd", "map_odometry.pcd", "poses.txt"})
    EXPECT_EQ(read_file_bytes(a + "/" + name), read_file_bytes(b + "/" + name)) << name;
}

TEST(LoopClosure3D, OnItsOwnThreadItClosesTheSameLoopsAsInline) {
  // (RunOdometryWritesTheLoopClosedRun runs the thread under the sanitizers.)
  if (scanmatch::testing::sanitized()) GTEST_SKIP() << "the loop twice: too slow sanitized";
  scanmatch::testing::TempDir dir;
  const auto threaded_source = short_campus_loop_sequence();
  const RunSummary threaded = run_with_loop_closure(*threaded_source, dir.file("thread"));
  const auto inline_source = short_campus_loop_sequence();
  RunOptions inline_options;
  inline_options.loop_closure_thread = false;
  const RunSummary inline_run =
      run_with_loop_closure(*inline_source, dir.file("inline"), inline_options);
  ASSERT_TRUE(threaded.loop_closure && inline_run.loop_closure);
  EXPECT_GT(threaded.loop_closure->accepted, 0u);  // so that the comparison means something
  EXPECT_EQ(threaded.loop_closure->accepted, inline_run.loop_closure->accepted);
  ASSERT_EQ(threaded.optimized_poses.size(), inline_run.optimized_poses.size());
  for (std::size_t i = 0; i < threaded.optimized_poses.size(); ++i)
    EXPECT_EQ(threaded.optimized_poses[i].matrix(), inline_run.optimized_poses[i].matrix()) << i;
  expect_same_loop_closed_runs(dir.file("thread"), dir.file("inline"));
  EXPECT_TRUE(threaded.loop_closure->thread);
  EXPECT_FALSE(inline_run.loop_closure->thread);
  const auto summary = [&](const std::string& name) {
    return nlohmann::json::parse(std::ifstream(dir.file(name + "/summary.json")));
  };
  EXPECT_TRUE(summary("thread")["loop_closure"]["thread"].get<bool>());
  EXPECT_FALSE(summary("inline")["loop_closure"]["thread"].get<bool>());
  EXPECT_EQ(summary("inline")["loop_closure"]["wait_ms_per_frame"].get<double>(), 0.0);
}

// Delivers a source's frames and raises `stop` after the `after`-th, as Ctrl-C would mid-run.
class StoppingSource : public SequenceSource {
 public:
  StoppingSource(std::unique_ptr<SequenceSource> source, std::size_t after, std::atomic<bool>& stop)
      : source_(std::move(source)), after_(after), stop_(stop) {}
  std::size_t size() const override { return source_->size(); }
  bool next(Frame& frame) override {
    if (!source_->next(frame)) return false;
    if (++delivered_ == after_) stop_ = true;
    return true;
  }
  std::optional<Trajectory> ground_truth() const override { return source_->ground_truth(); }
  std::string describe() const override { return source_->describe(); }

 private:
  std::unique_ptr<SequenceSource> source_;
  std::size_t after_, delivered_ = 0;
  std::atomic<bool>& stop_;
};

TEST(LoopClosure3D, AnInterruptedRunStillWorksTheFramesQueuedForLoopClosure) {
  scanmatch::testing::TempDir dir;
  constexpr std::size_t kFrames = 60;
  for (const bool thread : {true, false}) {
    std::atomic<bool> stop{false};
    StoppingSource source(short_campus_loop_sequence(), kFrames, stop);
    RunOptions run;
    run.loop_closure_thread = thread;
    run.stop = &stop;
    const RunSummary summary =
        run_with_loop_closure(source, dir.file(thread ? "thread" : "inline"), run);
    EXPECT_TRUE(summary.interrupted);
    EXPECT_EQ(summary.frames, kFrames);
    EXPECT_EQ(summary.optimized_poses.size(), kFrames) << thread;
  }
  expect_same_loop_closed_runs(dir.file("thread"), dir.file("inline"));
}

}  // namespace
}  // namespace scanmatch
