#include "scanmatch/benchmark/benchmark.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/svg_plot.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/odometry/preprocessor.hpp"
#include "scanmatch/registration/methods.hpp"
#include "scanmatch/run/report.hpp"
#include "scanmatch/sim/open_sequence.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace scanmatch {
namespace {

namespace fs = std::filesystem;

std::string machine_description() {
  std::string cpu = "unknown CPU";
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  return fmt::format("{}, {} hardware threads", cpu, std::thread::hardware_concurrency());
}

BenchmarkCell run_cell(const BenchmarkVariant& v, const std::string& name,
                       const std::string& data_folder, const std::string& reference,
                       const BenchmarkOptions& o) {
  BenchmarkCell cell;
  cell.folder = o.out + "/runs/" + name + "/" + variant_folder_name(v.name);
  if (!v.not_built.empty()) {
    cell.not_built = true;
    cell.error = "not built";
    return cell;
  }
  try {
    SequenceOptions input;
    input.reference = reference;
    auto source = open_sequence(data_folder, input);
    RunOptions run;
    run.out_dir = cell.folder;
    run.max_frames = o.frames;
    run.quiet = o.quiet;
    if (!o.quiet) std::fprintf(stderr, "bench: %s on %s\n", v.name.c_str(), name.c_str());
    cell.run = run_odometry(*source, v.config, run);
    if (cell.run.ate) {
      cell.ate = *cell.run.ate;
      const std::vector<Pose>& gt = cell.run.ground_truth;
      const std::vector<Pose> est(cell.run.poses.begin(),
                                  cell.run.poses.begin() + static_cast<std::ptrdiff_t>(gt.size()));
      cell.kitti = compute_kitti_drift(gt, est);
    }
    cell.accuracy_score = accuracy_score(data_folder, cell.run.poses);
    cell.ok = true;
  } catch (const Error& e) {
    cell.error = e.what();
    std::fprintf(stderr, "bench: %s on %s failed: %s\n", v.name.c_str(), name.c_str(), e.what());
  }
  return cell;
}

// tables.md and tables.csv, report.html with the tables, one report per sequence.
std::string write_outputs(const BenchmarkOptions& o, const BenchmarkResult& r) {
  std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::string md = fmt::format(
      "Command: `{}`\n\nMachine: {}. Date: {}. Frames per sequence: {}. Threads: {}.\n\n",
      o.command_line, machine_description(), date, o.frames > 0 ? std::to_string(o.frames) : "all",
      o.threads);
  for (const auto& s : r.sequences)
    if (!s.reference.empty()) md += fmt::format("Reference of {}: `{}`.\n\n", s.name, s.reference);
  for (const auto& v : r.variants)
    if (!v.not_built.empty())
      md += fmt::format("Not built into this binary: {} (configure with {}).\n\n", v.name,
                        v.not_built);
  std::string csv, html_tables;
  for (const auto& t : r.tables) {
    md += to_markdown(t);
    csv += to_csv(t);
    html_tables += to_html(t);
  }
  write_file_atomic(o.out + "/tables.md", md);
  write_file_atomic(o.out + "/tables.csv", csv);
  for (const auto& s : r.sequences) {
    std::vector<RunFolder> runs;
    for (const auto& v : r.variants)
      if (s.cells.at(v.name).ok) runs.push_back(read_run_folder(s.cells.at(v.name).folder));
    if (runs.empty()) continue;
    ReportOptions report;
    report.title = "scanmatch bench: " + s.name;
    if (&s == &r.sequences.front()) {
      report.preamble_html = "<p>" + html_escape(o.command_line) + "</p>" + html_tables;
      write_file_atomic(o.out + "/report.html", render_report(runs, std::nullopt, report));
    }
    report.preamble_html.clear();
    write_file_atomic(o.out + "/report_" + s.name + ".html",
                      render_report(runs, std::nullopt, report));
  }
  return md;
}

}  // namespace

std::vector<BenchmarkVariant> benchmark_variants(const std::vector<std::string>& methods,
                                                 int threads, bool ablation) {
  std::vector<BenchmarkVariant> v;
  for (const auto& method : methods) {
    OdometryConfig c;
    c.method = method;
    c.threads = threads;
    // A known peer this build lacks is listed as such; anything else unusable stops here.
    const std::string missing = missing_peer_option(method);
    if (missing.empty()) make_frame_odometry(c);
    v.push_back({method, c, missing});
  }
  if (ablation && std::find(methods.begin(), methods.end(), "ctf-icp") != methods.end()) {
    OdometryConfig c;
    c.threads = threads;
    c.fine_stage = false;
    v.push_back({"ctf-icp --no-fine", c, ""});
    c.fine_stage = true;
    c.map_update = false;
    v.push_back({"ctf-icp --no-map-update", c, ""});
  }
  return v;
}

std::string variant_folder_name(const std::string& variant) {
  std::string dir_name;
  bool word_start = true;
  for (const char ch : variant) {
    if (ch == ' ') {
      if (!dir_name.empty() && dir_name.back() != '_') dir_name += '_';
      word_start = true;
    } else if (!(word_start && ch == '-')) {
      dir_name += ch;
      word_start = false;
    }
  }
  return dir_name;
}

std::string cached_dataset(const std::string& preset, const std::string& data, std::size_t frames,
                           bool quiet) {
  sim::preset_info(preset);  // validates the name
  const std::string folder = data + "/" + preset;
  bool reuse = fs::exists(folder + "/dataset.json");
  if (reuse) {
    // A data set written earlier with fewer frames than asked is written again.
    const auto source = open_sequence_folder(folder);
    reuse = frames > 0 ? source->size() >= frames : true;
  }
  if (!reuse) {
    sim::SimOptions sim;
    sim.preset = preset;
    if (frames > 0) sim.frames = frames;
    if (!quiet)
      std::fprintf(stderr, "bench: simulating %s into %s\n", preset.c_str(), folder.c_str());
    sim::write_dataset(sim::Simulator(sim), folder, quiet);
  }
  return folder;
}

double accuracy_score(const std::string& sequence, const std::vector<Pose>& poses) {
  if (poses.size() < 2) return 0.0;
  auto source = open_sequence(sequence);
  // The score's own frames, the same whatever the method's preprocessing: 0.25 m voxels, no crop.
  PreprocessOptions options;
  options.min_range = 0.0;
  options.max_range = std::numeric_limits<double>::infinity();
  options.voxel_size = 0.25;
  options.min_downsampled_points = 0;
  options.keep_attributes = false;
  Preprocessor scoring(options);
  const std::size_t step = std::max<std::size_t>(1, poses.size() / 30);
  double sum = 0.0;
  std::size_t pairs = 0;
  Frame frame;
  PointCloud previous;
  for (std::size_t i = 0; i < poses.size() && source->next(frame); ++i) {
    const bool wanted = i % step == 0 || (i + 1 < poses.size() && (i + 1) % step == 0);
    if (!wanted) continue;
    PointCloud down = scoring.process(frame.cloud);
    if (i % step == 0 && i > 0 && !previous.empty()) {
      sum += fitness_score(down, previous, poses[i - 1].inverse() * poses[i], 1.0);
      ++pairs;
    }
    previous = std::move(down);
  }
  return pairs > 0 ? sum / static_cast<double>(pairs) : 0.0;
}

BenchmarkResult run_benchmark(BenchmarkOptions o) {
  if (o.out.empty()) throw Error("bench: no output folder given");
  if (o.presets.empty() && o.sequences.empty())
    o.presets = {"static-indoor", "static-outdoor", "dynamic-indoor", "dynamic-outdoor",
                 "dynamic-outdoor-fast"};
  if (o.methods.empty())
    o.methods = {"ctf-icp",        "icp",          "ndt", "gicp", "vgicp", "loam",
                 "point-to-plane", "point-to-line"};
  BenchmarkResult result;
  result.variants = benchmark_variants(o.methods, o.threads, o.ablation);
  if (o.data.empty()) o.data = o.out + "/data";
  fs::create_directories(o.out);
  if (!o.references.empty() && o.references.size() != o.sequences.size())
    throw Error(
        fmt::format("bench: {} reference files for {} sequences (give one per sequence, "
                    "in order)",
                    o.references.size(), o.sequences.size()));
  struct Input {
    std::string name, spec, reference;
  };
  std::vector<Input> sequences;
  for (const auto& preset : o.presets)
    sequences.push_back({preset, cached_dataset(preset, o.data, o.frames, o.quiet), ""});
  for (std::size_t i = 0; i < o.sequences.size(); ++i) {
    std::string reference = o.references.empty() ? "" : o.references[i];
    // A reference kept beside the frames (avia_hku1's odom_poses.txt) serves when the source
    // has no ground truth of its own.
    if (reference.empty()) {
      const std::string beside = reference_beside(o.sequences[i]);
      if (!beside.empty() && !open_sequence(o.sequences[i])->ground_truth()) reference = beside;
      if (!reference.empty() && !o.quiet)
        std::fprintf(stderr, "bench: %s: reference %s (found beside the frames)\n",
                     o.sequences[i].c_str(), reference.c_str());
    }
    fs::path path = fs::path(o.sequences[i]).lexically_normal();
    if (path.filename().empty()) path = path.parent_path();  // "folder/"
    sequences.push_back({path.filename().string(), o.sequences[i], reference});
  }

  for (const auto& [name, folder, reference] : sequences) {
    BenchmarkSequence sequence;
    sequence.name = name;
    sequence.data_folder = folder;
    sequence.reference = reference;
    for (const auto& v : result.variants) {
      BenchmarkCell cell = run_cell(v, name, folder, reference, o);
      if (cell.run.ate) {
        sequence.path_length = cell.ate.path_length;
        sequence.still = cell.ate.path_length < 1e-3;
      }
      sequence.cells[v.name] = std::move(cell);
    }
    result.sequences.push_back(std::move(sequence));
  }
  result.tables = benchmark_tables(result.sequences, result.variants, o.methods);
  result.markdown = write_outputs(o, result);
  return result;
}

}  // namespace scanmatch
