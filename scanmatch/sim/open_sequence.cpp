#include "scanmatch/sim/open_sequence.hpp"

#include <filesystem>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/bag/bag_sequence.hpp"
#include "scanmatch/io/trajectory.hpp"

namespace scanmatch {
namespace {

// A source whose ground truth is replaced by a trajectory read from a file.
class ReferencedSequence : public SequenceSource {
 public:
  ReferencedSequence(std::unique_ptr<SequenceSource> source, Trajectory reference,
                     std::string reference_path)
      : source_(std::move(source)),
        reference_(std::move(reference)),
        reference_path_(std::move(reference_path)) {}

  std::size_t size() const override { return source_->size(); }
  bool next(Frame& frame) override { return source_->next(frame); }
  std::optional<Trajectory> ground_truth() const override { return reference_; }
  std::string describe() const override {
    return source_->describe() + ", reference " + reference_path_;
  }

 private:
  std::unique_ptr<SequenceSource> source_;
  Trajectory reference_;
  std::string reference_path_;
};

std::unique_ptr<SequenceSource> open_source(const std::string& spec,
                                            const SequenceOptions& options) {
  if (is_simulator_spec(spec)) {
    sim::SimOptions simulator = options.simulator;
    simulator.preset = spec.substr(4);
    return sim::simulated_sequence(simulator);
  }
  std::error_code ec;
  if (!std::filesystem::exists(spec, ec))
    throw Error(spec + ": no such sequence (a folder, a KITTI sequence, a bag or sim:PRESET)");
  if (is_bag_path(spec)) return open_bag_sequence(spec, options.topic);
  return open_sequence_folder(spec, options.cloud);
}

}  // namespace

std::string reference_beside(const std::string& spec) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (is_simulator_spec(spec) || !fs::is_directory(spec, ec)) return "";
  for (const char* name : {"odom_poses.txt", "reference_poses.txt"})
    if (fs::is_regular_file(fs::path(spec) / name, ec)) return (fs::path(spec) / name).string();
  return "";
}

bool is_simulator_spec(const std::string& spec) {
  return spec.rfind("sim:", 0) == 0;
}

std::unique_ptr<SequenceSource> open_sequence(const std::string& spec,
                                              const SequenceOptions& options) {
  std::unique_ptr<SequenceSource> source = open_source(spec, options);
  if (options.reference.empty()) return source;
  Trajectory reference = read_trajectory(options.reference);
  if (reference.size() != source->size())
    fail(options.reference, "has " + std::to_string(reference.size()) + " poses for the " +
                                std::to_string(source->size()) + " frames of " + spec);
  // Runs give poses in the world frame of the first frame; another system's reference need not.
  const Pose first_inverse = reference.poses.front().inverse();
  for (Pose& pose : reference.poses) pose = first_inverse * pose;
  return std::make_unique<ReferencedSequence>(std::move(source), std::move(reference),
                                              options.reference);
}

}  // namespace scanmatch
