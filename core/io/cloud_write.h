// Point-cloud encoders for the files WritePointCloud writes (io_point_cloud.h).
//
// The layouts are PCL 1.13's (its PCDWriter and binary PLYWriter), byte for
// byte, so files read the same by PCL, CloudCompare and older surfinspect
// versions:
//   PCD: fields x y z as float32, the grid's WIDTH and HEIGHT, identity
//        VIEWPOINT; ascii values with 9 significant digits ("nan" for no
//        data); binary data followed by zeros, as many as the header
//        falls short of 4096 bytes, as PCL's memory-mapped writer leaves it;
//        binary_compressed: the x, y and z planes one after another, LZF
//        coded behind their compressed and decoded sizes (uint32). The LZF
//        stream is our own encoder's (lzf.h), so those bytes differ from
//        PCL's; what they decode to does not.
//   PLY: the valid points only (PLY has no grid); binary little-endian with
//        PCL's header, or ascii with 9 significant digits (PCL's ascii
//        writer prints only 6, which rounds millimetres to ~0.1 mm).
#pragma once

#include <string>
#include <string_view>

#include "core/types/point_cloud.h"

namespace surfinspect {

enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };

// The whole file. `cloud` must pass Validate(); for binary_compressed its
// planes and their LZF stream must fit the format's uint32 sizes
// (WritePointCloud refuses clouds of more than 2^32 / 24 points).
// A non-empty `unit` adds one comment line naming the coordinates' unit
// ("# units: mm" after the PCD's first line, "comment units: mm" after the
// PLY's first comment); without it the bytes are PCL's.
std::string EncodePcd(const PointCloud& cloud, PcdEncoding encoding, std::string_view unit = "");
std::string EncodePly(const PointCloud& cloud, bool binary, std::string_view unit = "");

}  // namespace surfinspect
