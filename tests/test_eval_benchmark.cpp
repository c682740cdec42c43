// The benchmarks as library calls: variants and their folders, the data-set cache, the tables
// built from results, a tiny `bench` run, and the 2D benchmark's tables.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "scanmatch/benchmark/benchmark.hpp"
#include "scanmatch/benchmark/benchmark2d.hpp"
#include "scanmatch/core/error.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::read_text;
using scanmatch::testing::TempDir;

namespace {

const ResultTable* table_titled(const std::vector<ResultTable>& tables, const std::string& start) {
  for (const ResultTable& t : tables)
    if (t.title.rfind(start, 0) == 0) return &t;
  return nullptr;
}

BenchmarkCell finished(double ate_percent, double final_drift, double max, std::size_t bridged) {
  BenchmarkCell c;
  c.ok = true;
  c.ate.rmse_percent_of_path = ate_percent;
  c.ate.final_drift = final_drift;
  c.ate.max = max;
  c.run.bridged_frames = bridged;
  c.run.frames_per_second = 12.34;
  c.accuracy_score = 0.5;
  return c;
}

}  // namespace

TEST(Benchmark, VariantsAddTheAblationsOfCtfIcpAndNameTheirFolders) {
  const auto v = benchmark_variants({"ctf-icp", "ndt"}, 2, true);
  ASSERT_EQ(v.size(), 4u);
  EXPECT_EQ(v[2].name, "ctf-icp --no-fine");
  EXPECT_FALSE(v[2].config.fine_stage);
  EXPECT_FALSE(v[3].config.map_update);
  EXPECT_EQ(v[1].config.threads, 2);
  EXPECT_EQ(benchmark_variants({"ndt"}, 1, true).size(), 1u);  // no ctf-icp, no ablation
  EXPECT_EQ(benchmark_variants({"ctf-icp"}, 1, false).size(), 1u);
  EXPECT_EQ(variant_folder_name("ctf-icp --no-map-update"), "ctf-icp_no-map-update");
  EXPECT_EQ(variant_folder_name("point-to-plane"), "point-to-plane");
  try {
    benchmark_variants({"ndt", "magic"}, 1, true);
    FAIL() << "unknown method accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("magic"), std::string::npos) << e.what();
  }
}

TEST(Benchmark, TablesPutEachSequenceAndVariantInItsCell) {
  const auto variants = benchmark_variants({"ctf-icp", "ndt"}, 1, true);
  BenchmarkSequence moving{"moving", "", "", false, 100.0, {}};
  moving.cells["ctf-icp"] = finished(1.23456, 0, 0, 2);
  moving.cells["ndt"].error = "diverged";  // failed
  moving.cells["ctf-icp --no-fine"] = finished(4.0, 0, 0, 0);
  moving.cells["ctf-icp --no-map-update"] = finished(5.0, 0, 0, 0);
  BenchmarkSequence still{"still", "", "", true, 0.0, {}};
  still.cells["ctf-icp"] = finished(0, 0.01, 0.02, 0);
  const auto tables = benchmark_tables({moving, still}, variants, {"ctf-icp", "ndt"});

  const ResultTable* ate = table_titled(tables, "ATE RMSE");
  ASSERT_NE(ate, nullptr);
  ASSERT_EQ(ate->rows.size(), 1u);
  EXPECT_EQ(ate->rows[0], (std::vector<std::string>{"moving", "1.235 (2 bridged)", "failed"}));
  const ResultTable* drift = table_titled(tables, "Still sensor");
  ASSERT_NE(drift, nullptr);
  EXPECT_EQ(drift->rows.at(0), (std::vector<std::string>{"still", "0.0100 / 0.0200", ""}));
  const ResultTable* ablation = table_titled(tables, "Ablation");
  ASSERT_NE(ablation, nullptr);
  EXPECT_EQ(ablation->rows.at(0), (std::vector<std::string>{"moving", "4.000", "5.000", "1.235"}));
  const ResultTable* fps = table_titled(tables, "Frames per second");
  ASSERT_NE(fps, nullptr);
  EXPECT_EQ(fps->rows.size(), 2u);
  EXPECT_EQ(fps->rows[0][1], "12.3");
  const ResultTable* side = table_titled(tables, "ATE and frames per second side by side");
  ASSERT_NE(side, nullptr);
  EXPECT_EQ(side->header,
            (std::vector<std::string>{"method", "moving ATE %", "moving frames/s"}));  // not still
  EXPECT_EQ(side->rows.at(0), (std::vector<std::string>{"ctf-icp", "1.235 (2 bridged)", "12.3"}));
  EXPECT_EQ(side->rows.at(1), (std::vector<std::string>{"ndt", "failed", "failed"}));
  // No path reached the 100 m of a KITTI segment: the drift table only shows because a run
  // failed, and without the ablation variants there is no ablation table.
  const ResultTable* kitti = table_titled(tables, "KITTI drift");
  ASSERT_NE(kitti, nullptr);
  EXPECT_EQ(kitti->rows.at(0), (std::vector<std::string>{"moving", "-", "failed"}));
  const auto plain =
      benchmark_tables({moving}, benchmark_variants({"ctf-icp"}, 1, false), {"ctf-icp"});
  EXPECT_EQ(table_titled(plain, "KITTI drift"), nullptr);
  EXPECT_EQ(table_titled(plain, "Ablation"), nullptr);
  EXPECT_NE(table_titled(plain, "Accuracy score"), nullptr);
}

TEST(Benchmark, SimulatedDataSetsAreKeptAndRewrittenWhenTooShort) {
  TempDir dir;
  const std::string data = dir.file("data");
  const auto frames_in = [](const std::string& folder) {
    return open_sequence_folder(folder)->size();
  };
  const std::string folder = cached_dataset("static-indoor", data, 3, true);
  EXPECT_EQ(folder, data + "/static-indoor");
  EXPECT_EQ(frames_in(folder), 3u);
  EXPECT_EQ(frames_in(cached_dataset("static-indoor", data, 2, true)), 3u);  // reused
  EXPECT_EQ(frames_in(cached_dataset("static-indoor", data, 4, true)), 4u);  // written again
  EXPECT_THROW(cached_dataset("no-such-preset", data, 2, true), Error);
}

TEST(Benchmark, ATinyRunWritesItsTablesAndRunFolders) {
  TempDir dir;
  BenchmarkOptions o;
  o.presets = {"static-indoor"};
  o.methods = {"ndt"};
  o.frames = 3;
  o.quiet = true;
  o.out = dir.file("b");
  o.command_line = "test";
  const BenchmarkResult r = run_benchmark(o);
  ASSERT_EQ(r.sequences.size(), 1u);
  const BenchmarkSequence& s = r.sequences[0];
  EXPECT_TRUE(s.still);
  ASSERT_TRUE(s.cells.at("ndt").ok) << s.cells.at("ndt").error;
  EXPECT_EQ(s.cells.at("ndt").run.frames, 3u);
  EXPECT_EQ(s.cells.at("ndt").folder, dir.file("b/runs/static-indoor/ndt"));
  EXPECT_TRUE(std::filesystem::exists(dir.file("b/runs/static-indoor/ndt/poses_gt.txt")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("b/data/static-indoor/dataset.json")));
  EXPECT_EQ(read_text(dir.file("b/tables.md")), r.markdown);
  EXPECT_NE(r.markdown.find("Command: `test`"), std::string::npos);
  EXPECT_NE(r.markdown.find("| static-indoor |"), std::string::npos);
  EXPECT_NE(table_titled(r.tables, "Still sensor"), nullptr);
  EXPECT_TRUE(std::filesystem::exists(dir.file("b/report_static-indoor.html")));
}

TEST(Benchmark, SequencesTakeTheirGroundTruthFromReferenceFiles) {
  TempDir dir;
  const std::string data = cached_dataset("static-indoor", dir.file("data"), 3, true);
  BenchmarkOptions o;
  o.sequences = {data + "/frames"};  // frames only: no ground truth of their own
  o.references = {data + "/poses_gt.txt"};
  o.methods = {"ndt"};
  o.ablation = false;
  o.quiet = true;
  o.out = dir.file("b");
  const BenchmarkResult r = run_benchmark(o);
  ASSERT_EQ(r.sequences.size(), 1u);
  const BenchmarkCell& cell = r.sequences[0].cells.at("ndt");
  ASSERT_TRUE(cell.ok) << cell.error;
  EXPECT_TRUE(cell.run.ate.has_value());
  EXPECT_EQ(cell.run.ground_truth.size(), 3u);

  o.references.push_back(data + "/poses_gt.txt");  // two references for one sequence
  try {
    run_benchmark(o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("2 reference files for 1 sequences"), std::string::npos)
        << e.what();
  }
}

TEST(Benchmark2D, PairTableHasOneRowPerMethodAndIsWrittenAsPrinted) {
  TempDir dir;
  Benchmark2DOptions o;
  o.methods = {"icp", kSparseIcpPaper};
  o.pairs = 4;
  o.quiet = true;
  o.out = dir.file("out");
  std::vector<std::string> printed;
  const std::string md =
      run_benchmark2d(o, [&](const std::string& table) { printed.push_back(table); });
  ASSERT_EQ(printed.size(), 1u);
  EXPECT_EQ(printed[0], md);
  EXPECT_EQ(read_text(dir.file("out/planar_tables.md")), md);
  EXPECT_NE(md.find("4 pairs of Neato scans"), std::string::npos);
  EXPECT_NE(md.find("\n| icp | "), std::string::npos);
  EXPECT_NE(md.find("\n| sparse-icp-paper | "), std::string::npos);
  o.methods = {"icp", "magic"};
  EXPECT_THROW(run_benchmark2d(o), Error);
}

TEST(Benchmark2D, TheExtraMethodNamesAreSparseIcpAndPlIcpVariants) {
  const Registration2DOptions paper = benchmark2d_method(kSparseIcpPaper);
  EXPECT_EQ(paper.method, "sparse-icp");
  EXPECT_EQ(paper.sparse_step, "svd");
  EXPECT_TRUE(paper.coarse_translation);
  const Registration2DOptions fitted = benchmark2d_method(kPlIcpFitted);
  EXPECT_EQ(fitted.method, "pl-icp");
  EXPECT_EQ(fitted.pl_line_radius, fitted.sparse_line_radius);
  EXPECT_EQ(benchmark2d_method("icp").method, "icp");
  EXPECT_THROW(benchmark2d_method("magic"), Error);
}
