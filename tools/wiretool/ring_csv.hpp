// The ring CSV of `wiretool mesh` and `wiretool view` (a contract, docs/wiretool.md): one row per ring record.
#pragma once

#include <wire/rings.hpp>

#include <cstddef>
#include <string>

namespace wiretool {

/// `mesh`'s header (no newline); `view` appends ",sides".
inline constexpr const char* kRingCsvHeader = "frame,wire,ring,segment,t,x,y,z,tx,ty,tz,nx,ny,nz,bx,by,bz,radius,u";

/// Appends one row per ring of `rings`: world centre (origin + double centre), the ring's double frame (t, r, s),
/// radius and double u; with sides >= 0 a last column `sides`.
void append_ring_rows(std::string& csv, std::size_t frame, std::size_t wire_index, const wire::RingSet& rings,
                      long sides = -1);

}  // namespace wiretool
