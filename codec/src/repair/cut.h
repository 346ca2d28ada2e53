// The manifold cut without its final check, for callers that check the result anyway.
#pragma once

#include "pomar/pomar.h"
#include "pomar/repair.h"

namespace pomar {

/// make_manifold() without building the cut mesh's corner table to check it: the lossless
/// stage's encoder builds that table next, and turns a refusal into still_invalid().
RepairReport cut_to_manifold(Mesh &mesh, RepairMap *map);

/// The internal error for a cut mesh that the corner table still refuses (a broken
/// invariant of make_manifold: see the argument in repair/make_manifold.cpp).
Error still_invalid(const Error &refusal);

} // namespace pomar
