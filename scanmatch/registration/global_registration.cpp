#include "scanmatch/registration/global_registration.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <numeric>

#include "scanmatch/core/alignment.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch {
namespace {

// Keypoints and their descriptors of one cloud.
struct Described {
  PointCloud keypoints;
  std::vector<FpfhDescriptor> descriptors;
};

Described describe_cloud(const PointCloud& cloud, const Eigen::Vector3d& viewpoint,
                         const GlobalRegistrationOptions& options) {
  const PointCloud down = voxel_downsample(cloud, options.feature_voxel_size);
  Described out;
  if (down.size() < 4) return out;
  const KdTree tree(down.points);
  FpfhOptions fpfh = options.fpfh;
  fpfh.viewpoint = viewpoint;
  fpfh.num_threads = options.num_threads;
  const std::vector<Eigen::Vector3d> normals =
      oriented_normals(down, tree, fpfh.normal_neighbours, viewpoint, options.num_threads);
  // Evenly thinned when there are too many: the cost of matching grows with their product.
  std::vector<std::size_t> keypoints;
  const std::size_t n = down.size(),
                    m = std::min(n, std::max<std::size_t>(options.max_keypoints, 1));
  for (std::size_t k = 0; k < m; ++k) keypoints.push_back(k * n / m);
  const std::vector<FpfhDescriptor> descriptors =
      compute_fpfh(down, tree, normals, keypoints, fpfh);
  for (std::size_t k = 0; k < keypoints.size(); ++k) {
    if (descriptors[k].isZero()) continue;  // too few neighbours to describe
    out.keypoints.points.push_back(down.points[keypoints[k]]);
    out.descriptors.push_back(descriptors[k]);
  }
  return out;
}

// For each descriptor of `a` the index of its nearest in `b`, and for each of `b` its nearest in
// `a`: exhaustive, the squared distances |x|^2 + |y|^2 - 2 x.y from one matrix product per block
// of `a` (in 33 dimensions a k-d tree visits most leaves anyway and was 2x slower).
void nearest_both_ways(const std::vector<FpfhDescriptor>& a, const std::vector<FpfhDescriptor>& b,
                       std::vector<std::size_t>& a_to_b, std::vector<std::size_t>& b_to_a) {
  const auto n = static_cast<Eigen::Index>(a.size()), m = static_cast<Eigen::Index>(b.size());
  Eigen::MatrixXf A(kFpfhBins, n), B(kFpfhBins, m);
  for (Eigen::Index i = 0; i < n; ++i) A.col(i) = a[static_cast<std::size_t>(i)];
  for (Eigen::Index j = 0; j < m; ++j) B.col(j) = b[static_cast<std::size_t>(j)];
  const Eigen::VectorXf a2 = A.colwise().squaredNorm().transpose();
  const Eigen::VectorXf b2 = B.colwise().squaredNorm().transpose();
  constexpr float kInfinity = std::numeric_limits<float>::infinity();
  std::vector<float> best_a(a.size(), kInfinity), best_b(b.size(), kInfinity);
  a_to_b.assign(a.size(), 0);
  b_to_a.assign(b.size(), 0);
  constexpr Eigen::Index kBlock = 256;
  Eigen::MatrixXf D;
  for (Eigen::Index first = 0; first < n; first += kBlock) {
    const Eigen::Index rows = std::min(kBlock, n - first);
    D.noalias() = A.middleCols(first, rows).transpose() * B;
    for (Eigen::Index j = 0; j < m; ++j)
      for (Eigen::Index r = 0; r < rows; ++r) {
        const auto i = static_cast<std::size_t>(first + r), jj = static_cast<std::size_t>(j);
        const float d = a2[first + r] + b2[j] - 2.0f * D(r, j);
        if (d < best_a[i]) {
          best_a[i] = d;
          a_to_b[i] = jj;
        }
        if (d < best_b[jj]) {
          best_b[jj] = d;
          b_to_a[jj] = i;
        }
      }
  }
}

struct Correspondences {
  std::vector<Eigen::Vector3d> source, target;
  std::size_t size() const { return source.size(); }
};

// Mutual nearest neighbours in descriptor space.
Correspondences match(const Described& source, const Described& target) {
  Correspondences out;
  if (source.descriptors.empty() || target.descriptors.empty()) return out;
  std::vector<std::size_t> forward, backward;
  nearest_both_ways(source.descriptors, target.descriptors, forward, backward);
  for (std::size_t i = 0; i < forward.size(); ++i) {
    if (backward[forward[i]] != i) continue;
    out.source.push_back(source.keypoints.points[i].cast<double>());
    out.target.push_back(target.keypoints.points[forward[i]].cast<double>());
  }
  return out;
}

// The consistency graph as bit rows: i ~ j when the correspondences keep their distance.
class ConsistencyGraph {
 public:
  ConsistencyGraph(const Correspondences& c, double noise_bound)
      : n_(c.size()), words_((n_ + 63) / 64), bits_(n_ * words_, 0), degree_(n_, 0) {
    for (std::size_t i = 0; i < n_; ++i)
      for (std::size_t j = i + 1; j < n_; ++j) {
        const double ds = (c.source[i] - c.source[j]).norm();
        const double dt = (c.target[i] - c.target[j]).norm();
        if (std::abs(ds - dt) > noise_bound) continue;
        set(i, j);
        set(j, i);
        ++degree_[i];
        ++degree_[j];
      }
  }
  std::size_t size() const { return n_; }
  std::size_t degree(std::size_t i) const { return degree_[i]; }

  /// A clique containing `seed`, grown by adding the candidates in `order` that stay consistent
  /// with every member so far.
  std::vector<std::size_t> grow_clique(std::size_t seed,
                                       const std::vector<std::size_t>& order) const {
    std::vector<std::uint64_t> allowed(row(seed), row(seed) + words_);
    std::vector<std::size_t> clique{seed};
    for (std::size_t c : order) {
      if (!((allowed[c / 64] >> (c % 64)) & 1u)) continue;
      clique.push_back(c);
      const std::uint64_t* r = row(c);
      for (std::size_t w = 0; w < words_; ++w) allowed[w] &= r[w];
    }
    return clique;
  }

 private:
  const std::uint64_t* row(std::size_t i) const { return bits_.data() + i * words_; }
  void set(std::size_t i, std::size_t j) {
    bits_[i * words_ + j / 64] |= std::uint64_t{1} << (j % 64);
  }
  std::size_t n_, words_;
  std::vector<std::uint64_t> bits_;
  std::vector<std::size_t> degree_;
};

struct Hypothesis {
  Pose transform = Pose::Identity();
  std::size_t clique = 0, inliers = 0;
};

Pose fit(const Correspondences& c, const std::vector<std::size_t>& members) {
  std::vector<Eigen::Vector3d> from, to;
  for (std::size_t i : members) {
    from.push_back(c.source[i]);
    to.push_back(c.target[i]);
  }
  return umeyama_alignment(from, to, false).transform;
}

std::vector<std::size_t> explained(const Correspondences& c, const Pose& T, double bound) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < c.size(); ++i)
    if ((T * c.source[i] - c.target[i]).norm() <= bound) out.push_back(i);
  return out;
}

// The clique's motion, re-fitted twice on every correspondence it explains.
Hypothesis hypothesis_of(const Correspondences& c, const std::vector<std::size_t>& clique,
                         double bound) {
  Hypothesis h;
  h.clique = clique.size();
  h.transform = fit(c, clique);
  std::vector<std::size_t> members = explained(c, h.transform, bound);
  for (int round = 0; round < 2 && members.size() >= 3; ++round) {
    h.transform = fit(c, members);
    members = explained(c, h.transform, bound);
  }
  h.inliers = members.size();
  return h;
}

bool same_motion(const Pose& a, const Pose& b, const GlobalRegistrationOptions& o) {
  const Pose d = a.inverse() * b;
  return d.translation().norm() <= o.distinct_translation &&
         rotation_angle(d) <= o.distinct_rotation;
}

void check_options(const GlobalRegistrationOptions& o) {
  const auto bad = [](const std::string& what) { fail("global registration", what); };
  if (!(o.feature_voxel_size > 0.0)) bad("the feature voxel size must be positive");
  if (!(o.fpfh.radius > 0.0)) bad("the FPFH radius must be positive");
  if (o.fpfh.normal_neighbours < 3) bad("normals need at least 3 neighbours");
  if (!(o.noise_bound > 0.0)) bad("the noise bound must be positive");
  if (o.min_inliers < 3) bad("at least 3 inliers are needed for a rigid motion");
  if (!(o.refine_voxel_size >= 0.0)) bad("the refinement voxel size must not be negative");
}

}  // namespace

RegistrationOptions global_refinement_defaults() {
  RegistrationOptions o;
  o.method = "vgicp";
  o.solver.max_iterations = 60;
  return o;
}

std::string GlobalRegistrationResult::summary() const {
  return fmt::format(
      "{} inliers of {} correspondences ({:.1f} %; clique {}; keypoints {} / {}), second motion {} "
      "(ambiguity {:.2f}), overlap {:.1f} %, fitness {:.4g} m^2",
      inliers, correspondences, 100.0 * inlier_ratio, clique_size, source_keypoints,
      target_keypoints, second_inliers, ambiguity, 100.0 * overlap, fitness);
}

GlobalRegistrationResult register_global(const PointCloud& source, const PointCloud& target,
                                         const GlobalRegistrationOptions& options) {
  if (source.empty()) fail("global registration", "the source cloud is empty");
  if (target.empty()) fail("global registration", "the target cloud is empty");
  check_options(options);
  GlobalRegistrationResult r;
  const auto give_up = [&r](const std::string& why) {
    r.success = false;
    r.failure = why;
    return r;
  };

  const Stopwatch feature_time;
  const Described s = describe_cloud(source, options.source_viewpoint, options);
  const Described t = describe_cloud(target, options.target_viewpoint, options);
  r.feature_ms = feature_time.ms();
  r.source_keypoints = s.keypoints.size();
  r.target_keypoints = t.keypoints.size();

  const Stopwatch matching_time;
  const Correspondences c = match(s, t);
  r.correspondences = c.size();
  if (c.size() < options.min_inliers)
    return give_up(
        fmt::format("too few feature matches ({} mutual, {} needed): too little "
                    "structure at {} m voxels",
                    c.size(), options.min_inliers, options.feature_voxel_size));

  const ConsistencyGraph graph(c, options.noise_bound);
  std::vector<std::size_t> order(c.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&graph](std::size_t a, std::size_t b) {
    return graph.degree(a) > graph.degree(b);
  });
  // Cliques grown from the best-connected correspondences in `candidates` (degree order).
  const auto hypotheses_from = [&](const std::vector<std::size_t>& candidates) {
    std::vector<Hypothesis> out;
    const std::size_t seeds =
        std::min(candidates.size(), std::max<std::size_t>(options.clique_seeds, 1));
    for (std::size_t k = 0; k < seeds; ++k) {
      if (graph.degree(candidates[k]) < 2) break;
      const std::vector<std::size_t> clique = graph.grow_clique(candidates[k], candidates);
      if (clique.size() < 3) continue;
      r.clique_size = std::max(r.clique_size, clique.size());
      out.push_back(hypothesis_of(c, clique, options.noise_bound));
    }
    return out;
  };
  const auto most_inliers = [](const std::vector<Hypothesis>& hs) {
    return std::max_element(hs.begin(), hs.end(), [](const Hypothesis& a, const Hypothesis& b) {
      return a.inliers < b.inliers;
    });
  };
  std::vector<Hypothesis> hypotheses = hypotheses_from(order);
  r.matching_ms = matching_time.ms();
  if (hypotheses.empty())
    return give_up(
        fmt::format("no three of the {} feature matches agree on a rigid motion", c.size()));
  const Hypothesis best = *most_inliers(hypotheses);
  // The runner-up: the best different motion, also among the matches the best leaves
  // unexplained (a second copy of a place may have no seed among the best-connected ones).
  std::vector<char> explained_by_best(c.size(), 0);
  for (std::size_t i : explained(c, best.transform, options.noise_bound)) explained_by_best[i] = 1;
  std::vector<std::size_t> rest;
  for (std::size_t i : order)
    if (!explained_by_best[i]) rest.push_back(i);
  const std::vector<Hypothesis> others = hypotheses_from(rest);
  hypotheses.insert(hypotheses.end(), others.begin(), others.end());
  // Counted on the matches the best leaves unexplained: a variant of the best motion (a few
  // degrees off about the inliers' centre) shares most of its matches and is no rival.
  for (const Hypothesis& h : hypotheses) {
    if (same_motion(h.transform, best.transform, options)) continue;
    std::size_t own = 0;
    for (std::size_t i : explained(c, h.transform, options.noise_bound))
      own += !explained_by_best[i];
    r.second_inliers = std::max(r.second_inliers, own);
  }
  r.matching_ms = matching_time.ms();
  r.inliers = best.inliers;
  r.inlier_ratio = static_cast<double>(r.inliers) / static_cast<double>(c.size());
  r.ambiguity = static_cast<double>(r.second_inliers) / static_cast<double>(r.inliers);
  r.coarse_transform = best.transform;
  r.transform = best.transform;
  if (r.inliers < options.min_inliers)
    return give_up(
        fmt::format("weak evidence: the best motion explains {} of {} feature matches "
                    "({} needed)",
                    r.inliers, c.size(), options.min_inliers));
  if (r.ambiguity > options.max_ambiguity)
    return give_up(
        fmt::format("ambiguous: a different motion explains {} matches against the "
                    "best's {} (ratio {:.2f} > {:.2f})",
                    r.second_inliers, r.inliers, r.ambiguity, options.max_ambiguity));

  const Stopwatch refine_time;
  const PointCloud fine_source = options.refine_voxel_size > 0.0
                                     ? voxel_downsample(source, options.refine_voxel_size)
                                     : source;
  const PointCloud fine_target = options.refine_voxel_size > 0.0
                                     ? voxel_downsample(target, options.refine_voxel_size)
                                     : target;
  if (options.refine) {
    try {
      r.refinement = register_clouds(fine_source, fine_target, options.refinement, r.transform);
      r.transform = r.refinement.transform;
    } catch (const Error& e) {
      return give_up(std::string("the refinement failed: ") + e.what());
    }
  }
  std::size_t matched = 0;
  r.fitness =
      fitness_score(fine_source, fine_target, r.transform, options.feature_voxel_size, &matched);
  r.overlap = static_cast<double>(matched) / static_cast<double>(fine_source.size());
  r.refine_ms = refine_time.ms();
  if (r.overlap < options.min_overlap)
    return give_up(
        fmt::format("the clouds hardly overlap under the result ({:.1f} % of source "
                    "points within {} m of the target, {:.1f} % needed)",
                    100.0 * r.overlap, options.feature_voxel_size, 100.0 * options.min_overlap));
  r.success = true;
  return r;
}

}  // namespace scanmatch
