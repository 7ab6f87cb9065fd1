// Coarser levels of a density grid, for tools and tracers that want a cheaper proxy far away.
// Private to bake/.
#pragma once

#include <openvdb/openvdb.h>

namespace pine::bake::detail {

/// The grid at twice the voxel size, by the rule the bake fills a voxel wider than R / 4 with
/// (bake_boughs.cpp): each voxel holds the extinction whose opacity over its mean chord l =
/// 2/3 of its size is the mean of its 2 x 2 x 2 children's, 1 - exp(-sigma_c l), absent children
/// counting as empty space. Children of one value keep it; where they differ the level holds
/// less than their mean (the mass), which spread evenly would cover more than they do.
/// Coarse voxel I covers fine voxels 2I + {0, 1}^3, so its centre is their mean centre: the
/// transform is scaled by 2 and shifted by half a fine voxel.
/// Written here, not with tools::MultiResGrid: that one is vertex-centred (coarse voxel I sits
/// on fine voxel 2I) and restricts by full weighting over 27 neighbours, which blurs and moves
/// the mass; here a coarse voxel is exactly the cell its children fill.
openvdb::FloatGrid::Ptr halveResolution(const openvdb::FloatGrid& fine);

}  // namespace pine::bake::detail
