// `scanmatch bench`: every method on every sequence in one run, on identical frames, and the
// papers' tables from the results (ATE, frames per second, stage times, ablation, static drift,
// KITTI drift, the LOAM paper's accuracy score and ms per frame), as Markdown, CSV and HTML.

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <thread>

#include "apps/commands.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/eval/report.hpp"
#include "scanmatch/eval/svg_plot.hpp"
#include "scanmatch/eval/table.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/odometry/run.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace scanmatch::cli {
namespace {

namespace fs = std::filesystem;

struct BenchOptions {
  std::vector<std::string> presets, sequences, methods;
  std::size_t frames = 0;
  int threads = 1;
  bool ablation = true, quiet = false;
  std::string out, data;
  std::string command_line;
};

struct Variant {
  std::string name;  ///< column name: the method, or "ctf-icp --no-fine" etc.
  OdometryConfig config;
};

struct Cell {
  bool ok = false;
  std::string error;
  RunSummary run;
  AteResult ate;
  KittiDriftResult kitti;
  double accuracy_score = 0.0;  ///< mean squared NN distance of consecutive frames, m^2
  std::string folder;
};

struct SequenceResult {
  std::string name, data_folder;
  bool still = false;
  double path_length = 0.0;
  std::map<std::string, Cell> cells;  ///< by variant name
};

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

// The LOAM paper's "accuracy score": after alignment, the mean squared distance from each point
// of a frame to its nearest neighbour in the previous frame (PCL's fitness score, pairs within
// 1 m), averaged over up to 30 evenly spread frame pairs.
double accuracy_score(const std::string& data_folder, const std::vector<Pose>& poses) {
  if (poses.size() < 2) return 0.0;
  auto source = open_sequence_folder(data_folder);
  const std::size_t step = std::max<std::size_t>(1, poses.size() / 30);
  double sum = 0.0;
  std::size_t pairs = 0;
  Frame frame;
  PointCloud previous;
  for (std::size_t i = 0; i < poses.size() && source->next(frame); ++i) {
    const bool wanted = i % step == 0 || (i + 1 < poses.size() && (i + 1) % step == 0);
    if (!wanted) continue;
    PointCloud down = voxel_downsample(frame.cloud, 0.25);
    if (i % step == 0 && i > 0 && !previous.empty()) {
      sum += fitness_score(down, previous, poses[i - 1].inverse() * poses[i], 1.0);
      ++pairs;
    }
    previous = std::move(down);
  }
  return pairs > 0 ? sum / static_cast<double>(pairs) : 0.0;
}

std::vector<Variant> variants(const BenchOptions& o) {
  std::vector<Variant> v;
  for (const auto& method : o.methods) {
    OdometryConfig c;
    c.method = method;
    c.threads = o.threads;
    Odometry check(c);  // rejects unknown methods before any work
    v.push_back({method, c});
  }
  if (o.ablation && std::find(o.methods.begin(), o.methods.end(), "ctf-icp") != o.methods.end()) {
    OdometryConfig c;
    c.threads = o.threads;
    c.fine_stage = false;
    v.push_back({"ctf-icp --no-fine", c});
    c.fine_stage = true;
    c.map_update = false;
    v.push_back({"ctf-icp --no-map-update", c});
  }
  return v;
}

std::string percent(double v) {
  return fmt::format("{:.3f}", v);
}

// Frames a method could not register and bridged with the motion prior: its accuracy figure
// then says little (a still sensor "stays" where every frame is bridged).
std::string bridged_note(const Cell& c) {
  return c.run.bridged_frames > 0 ? fmt::format(" ({} bridged)", c.run.bridged_frames) : "";
}

std::vector<ResultTable> make_tables(const std::vector<SequenceResult>& results,
                                     const std::vector<Variant>& vs,
                                     const std::vector<std::string>& methods) {
  const auto cell_text = [](const Cell* c, const std::function<std::string(const Cell&)>& f) {
    if (!c) return std::string("");
    return c->ok ? f(*c) : std::string("failed");
  };
  const auto find = [](const SequenceResult& r, const std::string& v) -> const Cell* {
    const auto it = r.cells.find(v);
    return it == r.cells.end() ? nullptr : &it->second;
  };
  std::vector<ResultTable> tables;
  std::vector<std::string> header = {"sequence"};
  header.insert(header.end(), methods.begin(), methods.end());

  ResultTable ate{"ATE RMSE, % of path length (CTF-ICP Table 2)",
                  "No alignment: both trajectories start at the identity.",
                  header,
                  {}};
  ResultTable fps{"Frames per second, single thread (CTF-ICP Table 4)",
                  "Pipeline time only (reading or simulating frames excluded).",
                  header,
                  {}};
  ResultTable kitti{"KITTI drift: translation % / rotation deg per 100 m",
                    "Devkit definition: segments of 100 to 800 m that the path allows.",
                    header,
                    {}};
  ResultTable still{"Still sensor: final / maximum drift (m)", "", header, {}};
  for (const auto& r : results) {
    std::vector<std::string> a{r.name}, f{r.name}, k{r.name}, s{r.name};
    for (const auto& m : methods) {
      const Cell* c = find(r, m);
      a.push_back(cell_text(
          c, [](const Cell& x) { return percent(x.ate.rmse_percent_of_path) + bridged_note(x); }));
      f.push_back(cell_text(
          c, [](const Cell& x) { return fmt::format("{:.1f}", x.run.frames_per_second); }));
      k.push_back(cell_text(c, [](const Cell& x) {
        return x.kitti.segments > 0 ? fmt::format("{:.2f} / {:.2f}", x.kitti.translation_percent,
                                                  x.kitti.rotation_deg_per_100m)
                                    : std::string("-");
      }));
      s.push_back(cell_text(c, [](const Cell& x) {
        return fmt::format("{:.4f} / {:.4f}", x.ate.final_drift, x.ate.max) + bridged_note(x);
      }));
    }
    (r.still ? still.rows : ate.rows).push_back(r.still ? s : a);
    fps.rows.push_back(f);
    if (!r.still) kitti.rows.push_back(k);
  }
  if (!ate.rows.empty()) tables.push_back(ate);
  if (!still.rows.empty()) tables.push_back(still);
  tables.push_back(fps);

  ResultTable stages{"CTF-ICP mean ms per stage (CTF-ICP Table 3)",
                     "",
                     {"sequence", "preprocess", "coarse", "fine", "map update", "total",
                      "max total", "points after downsampling"},
                     {}};
  for (const auto& r : results) {
    const Cell* c = find(r, "ctf-icp");
    if (!c || !c->ok) continue;
    double points = 0;
    for (const auto& s : c->run.stats)
      points +=
          static_cast<double>(s.points_downsampled) / static_cast<double>(c->run.stats.size());
    stages.rows.push_back(
        {r.name, fmt::format("{:.2f}", c->run.preprocess.mean_ms),
         fmt::format("{:.2f}", c->run.coarse.mean_ms), fmt::format("{:.2f}", c->run.fine.mean_ms),
         fmt::format("{:.2f}", c->run.map_update.mean_ms),
         fmt::format("{:.2f}", c->run.total.mean_ms), fmt::format("{:.1f}", c->run.total.max_ms),
         fmt::format("{:.0f}", points)});
  }
  if (!stages.rows.empty()) tables.push_back(stages);

  bool ablation = false;
  for (const auto& v : vs) ablation = ablation || v.name == "ctf-icp --no-fine";
  if (ablation) {
    ResultTable t{"Ablation, ATE % of path (CTF-ICP Table 5)",
                  "--no-map-update: the fine stage registers to the previous frame only.",
                  {"sequence", "without fine stage", "without map building and update", "full"},
                  {}};
    for (const auto& r : results) {
      if (r.still) continue;
      const auto p = [](const Cell& x) { return percent(x.ate.rmse_percent_of_path); };
      t.rows.push_back({r.name, cell_text(find(r, "ctf-icp --no-fine"), p),
                        cell_text(find(r, "ctf-icp --no-map-update"), p),
                        cell_text(find(r, "ctf-icp"), p)});
    }
    if (!t.rows.empty()) tables.push_back(t);
  }

  ResultTable loam{"Accuracy score (m^2) and ms per frame, mean / max (LOAM paper Tables 1, 2)",
                   "Accuracy score: mean squared nearest-neighbour distance between consecutive "
                   "frames after alignment (PCL's fitness score, pairs within 1 m), 30 frame "
                   "pairs per sequence; lower is better.",
                   {"sequence", "method", "accuracy score", "mean ms", "max ms"},
                   {}};
  for (const auto& r : results)
    for (const auto& m : methods) {
      const Cell* c = find(r, m);
      if (!c) continue;
      loam.rows.push_back(
          {r.name, m,
           cell_text(c, [](const Cell& x) { return fmt::format("{:.4f}", x.accuracy_score); }),
           cell_text(c, [](const Cell& x) { return fmt::format("{:.1f}", x.run.total.mean_ms); }),
           cell_text(c, [](const Cell& x) { return fmt::format("{:.1f}", x.run.total.max_ms); })});
    }
  tables.push_back(loam);
  bool any_kitti = false;
  for (const auto& row : kitti.rows)
    for (std::size_t i = 1; i < row.size(); ++i) any_kitti = any_kitti || row[i] != "-";
  if (any_kitti) tables.push_back(kitti);
  return tables;
}

void run_bench(BenchOptions o) {
  if (o.presets.empty() && o.sequences.empty())
    o.presets = {"static-indoor", "static-outdoor", "dynamic-indoor", "dynamic-outdoor",
                 "dynamic-outdoor-fast"};
  if (o.methods.empty())
    o.methods = {"ctf-icp",        "icp",          "ndt", "gicp", "vgicp", "loam",
                 "point-to-plane", "point-to-line"};
  const std::vector<Variant> vs = variants(o);
  if (o.data.empty()) o.data = o.out + "/data";
  fs::create_directories(o.out);
  std::vector<std::pair<std::string, std::string>> sequences;  // name, folder
  for (const auto& preset : o.presets) {
    sim::preset_info(preset);  // validates the name
    const std::string folder = o.data + "/" + preset;
    bool reuse = fs::exists(folder + "/dataset.json");
    if (reuse) {
      // A data set written earlier with fewer frames than asked is written again.
      const auto source = open_sequence_folder(folder);
      reuse = o.frames > 0 ? source->size() >= o.frames : true;
    }
    if (!reuse) {
      sim::SimOptions sim;
      sim.preset = preset;
      if (o.frames > 0) sim.frames = o.frames;
      if (!o.quiet)
        std::fprintf(stderr, "bench: simulating %s into %s\n", preset.c_str(), folder.c_str());
      sim::write_dataset(sim::Simulator(sim), folder, o.quiet);
    }
    sequences.emplace_back(preset, folder);
  }
  for (const auto& folder : o.sequences)
    sequences.emplace_back(fs::path(folder).lexically_normal().filename().string(), folder);

  std::atomic<bool> stop{false};
  std::vector<SequenceResult> results;
  for (const auto& [name, folder] : sequences) {
    SequenceResult result;
    result.name = name;
    result.data_folder = folder;
    for (const auto& v : vs) {
      Cell cell;
      // "ctf-icp --no-fine" -> "ctf-icp_no-fine": words joined by '_', option dashes dropped.
      std::string dir_name;
      bool word_start = true;
      for (const char ch : v.name) {
        if (ch == ' ') {
          if (!dir_name.empty() && dir_name.back() != '_') dir_name += '_';
          word_start = true;
        } else if (!(word_start && ch == '-')) {
          dir_name += ch;
          word_start = false;
        }
      }
      cell.folder = o.out + "/runs/" + name + "/" + dir_name;
      try {
        auto source = open_sequence_folder(folder);
        const auto truth = source->ground_truth();
        RunOptions run;
        run.out_dir = cell.folder;
        run.max_frames = o.frames;
        run.quiet = o.quiet;
        run.stop = &stop;
        if (!o.quiet) std::fprintf(stderr, "bench: %s on %s\n", v.name.c_str(), name.c_str());
        cell.run = run_odometry(*source, v.config, run);
        if (truth) {
          const std::size_t n = std::min(cell.run.poses.size(), truth->size());
          const std::vector<Pose> gt(truth->poses.begin(),
                                     truth->poses.begin() + static_cast<std::ptrdiff_t>(n));
          const std::vector<Pose> est(cell.run.poses.begin(),
                                      cell.run.poses.begin() + static_cast<std::ptrdiff_t>(n));
          cell.ate = compute_ate(gt, est);
          cell.kitti = compute_kitti_drift(gt, est);
          result.path_length = cell.ate.path_length;
          result.still = cell.ate.path_length < 1e-3;
          Trajectory t;
          t.poses = gt;
          write_trajectory(cell.folder + "/poses_gt.txt", t, TrajectoryFormat::kKitti);
        }
        cell.accuracy_score = accuracy_score(folder, cell.run.poses);
        cell.ok = true;
      } catch (const Error& e) {
        cell.error = e.what();
        std::fprintf(stderr, "bench: %s on %s failed: %s\n", v.name.c_str(), name.c_str(),
                     e.what());
      }
      result.cells[v.name] = std::move(cell);
    }
    results.push_back(std::move(result));
  }

  std::vector<std::string> columns;
  for (const auto& v : vs) columns.push_back(v.name);
  const std::vector<ResultTable> tables = make_tables(results, vs, o.methods);
  std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::string md = fmt::format(
      "Command: `{}`\n\nMachine: {}. Date: {}. Frames per sequence: {}. Threads: {}.\n\n",
      o.command_line, machine_description(), date, o.frames > 0 ? std::to_string(o.frames) : "all",
      o.threads);
  std::string csv, html_tables;
  for (const auto& t : tables) {
    md += to_markdown(t);
    csv += to_csv(t);
    html_tables += to_html(t);
  }
  write_file_atomic(o.out + "/tables.md", md);
  write_file_atomic(o.out + "/tables.csv", csv);
  for (const auto& r : results) {
    std::vector<RunFolder> runs;
    for (const auto& v : vs)
      if (r.cells.at(v.name).ok) runs.push_back(read_run_folder(r.cells.at(v.name).folder));
    if (runs.empty()) continue;
    ReportOptions report;
    report.title = "scanmatch bench: " + r.name;
    if (&r == &results.front()) {
      report.preamble_html = "<p>" + html_escape(o.command_line) + "</p>" + html_tables;
      write_file_atomic(o.out + "/report.html", render_report(runs, std::nullopt, report));
    }
    report.preamble_html.clear();
    write_file_atomic(o.out + "/report_" + r.name + ".html",
                      render_report(runs, std::nullopt, report));
  }
  std::printf("%s", md.c_str());
  std::printf("tables in %s/tables.md and tables.csv, report in %s/report.html\n", o.out.c_str(),
              o.out.c_str());
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  auto* cmd = app.add_subcommand(
      "bench", "Every method on every sequence in one run: the papers' tables and a report");
  cmd->add_option("--preset", o->presets,
                  "Simulator presets (default: the CTF-ICP paper's five data sets)");
  cmd->add_option("--sequence", o->sequences, "Sequence folders (with ground truth) to add");
  cmd->add_option("--method", o->methods,
                  "Methods (default: ctf-icp icp ndt gicp vgicp loam point-to-plane "
                  "point-to-line)");
  cmd->add_option("--frames", o->frames, "Frames per sequence (0: all)");
  cmd->add_option("--threads", o->threads, "Threads per method")->capture_default_str();
  cmd->add_flag("!--no-ablation", o->ablation, "Skip ctf-icp --no-fine and --no-map-update");
  cmd->add_option("--data", o->data, "Where simulated data sets are kept (default OUT/data)");
  cmd->add_option("--out", o->out, "Output folder")->required();
  cmd->add_flag("--quiet", o->quiet, "No progress");
  cmd->callback([o, cmd] {
    BenchOptions options = *o;
    options.command_line = "scanmatch bench";
    for (const auto& p : o->presets) options.command_line += " --preset " + p;
    for (const auto& s : o->sequences) options.command_line += " --sequence " + s;
    for (const auto& m : o->methods) options.command_line += " --method " + m;
    if (o->frames > 0) options.command_line += " --frames " + std::to_string(o->frames);
    options.command_line += " --threads " + std::to_string(o->threads);
    if (!o->ablation) options.command_line += " --no-ablation";
    options.command_line += " --out " + o->out;
    (void)cmd;
    run_bench(std::move(options));
  });
}

}  // namespace scanmatch::cli
