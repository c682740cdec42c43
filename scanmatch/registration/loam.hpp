#pragma once
// Feature ICP on LOAM features (docs/methods.md section 3): point-to-line residuals for edge points
// and point-to-plane residuals for planar points, with the paper's neighbour choice, on the shared
// solver. Methods "loam" (both), "loam-edge" and "loam-plane".

#include "scanmatch/features/loam_features.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch {

enum class LoamResiduals { kBoth, kEdgesOnly, kPlanesOnly };

/// Registers two feature sets (the target's searched with k-d trees).
RegistrationResult register_loam_features(const LoamFeatures& source, const LoamFeatures& target,
                                          LoamResiduals residuals,
                                          const RegistrationOptions& options, const Pose& initial);

/// Extracts features of both clouds and registers them.
RegistrationResult register_loam(const PointCloud& source, const PointCloud& target,
                                 LoamResiduals residuals, const RegistrationOptions& options,
                                 const Pose& initial);

}  // namespace scanmatch
