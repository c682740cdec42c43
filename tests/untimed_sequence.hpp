#pragma once
// A sequence whose frames lose their point times, as KITTI's raw .bin scans come: for tests that
// run simulated spinning scans the way such recordings reach the odometry.

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "scanmatch/io/sequence.hpp"

namespace scanmatch::testing {

class UntimedSequence : public SequenceSource {
 public:
  explicit UntimedSequence(std::unique_ptr<SequenceSource> inner) : inner_(std::move(inner)) {}
  std::size_t size() const override { return inner_->size(); }
  bool next(Frame& frame) override {
    if (!inner_->next(frame)) return false;
    frame.cloud.time.clear();
    return true;
  }
  std::optional<Trajectory> ground_truth() const override { return inner_->ground_truth(); }
  std::string describe() const override { return "untimed " + inner_->describe(); }

 private:
  std::unique_ptr<SequenceSource> inner_;
};

}  // namespace scanmatch::testing
