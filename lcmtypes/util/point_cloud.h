// The two point-cloud message types, which lcmtypes/util codes array by array
// (point_cloud_codec.cc): Decode<T> (decode.h) and Encode<T> (encode.h) choose that path for them.
#pragma once

#include <type_traits>

namespace vtrack {
class ladar_scan_t;
class ladar_slice_t;
}  // namespace vtrack

namespace vtrack::lcm_util {

template <class T>
inline constexpr bool kIsPointCloud =
    std::is_same_v<T, ladar_scan_t> || std::is_same_v<T, ladar_slice_t>;

}  // namespace vtrack::lcm_util
