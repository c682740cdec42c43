#pragma once
// The options every 3D registration method takes (one plain struct; methods.hpp lists the
// methods and which fields each reads).

#include <string>

#include "scanmatch/features/loam_features.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct RegistrationOptions {
  std::string method = "gicp";               ///< a name from registration_methods() (methods.hpp)
  double max_correspondence_distance = 1.0;  ///< m, point-based methods
  int normal_neighbours = 10;                ///< k for normals (point-to-plane)
  int covariance_neighbours = 20;            ///< k for covariances (gicp, vgicp)
  double gicp_epsilon = 1e-3;                ///< smallest normalised eigenvalue of GICP covariances
  double voxel_resolution = 1.0;    ///< m, the Gaussian voxel map of vgicp, ndt and ctf-fine
  int voxel_neighbours = 0;         ///< 1, 7 or 27 voxels per point; 0: the method's default
                                    ///< (ndt 7, vgicp 1, ctf-fine 1)
  double ndt_outlier_ratio = 0.55;  ///< Magnusson's outlier probability for the score constants
  double ctf_epsilon = 1e-6;        ///< CTF-ICP's normalised smallest eigenvalue
  LoamFeatureOptions loam;          ///< feature extraction of the loam methods
  SolverOptions solver;
};

/// `register`'s configuration: both clouds are voxel-downsampled, then registered.
struct PairRegistrationOptions {
  double voxel_size = 0.1;  ///< m; 0: no downsampling
  RegistrationOptions registration;
};

}  // namespace scanmatch
