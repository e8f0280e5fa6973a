// Error maps from Zygo MetroPro `.dat` files.
#include <fmt/core.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "core/error.h"
#include "polishing/error_map_io.h"
#include "polishing/error_map_io_impl.h"

namespace arcwheel::polishing {
namespace {

using namespace internal;

// MetroPro .dat. Layout: MetroPro Reference Guide (Zygo OMP-0347, appendix B "Data File Format"),
// as read by Gwyddion's modules/file/metropro.c and prysm's read_zygo_dat. Byte offsets of the
// big-endian header fields used here; they are the same in header formats 1, 2 and 3.
struct MetroProField {
  const char* name;
  std::size_t offset;
};
constexpr MetroProField kMagic{"magic_number", 0};               // uint32
constexpr MetroProField kHeaderFormat{"header_format", 4};       // uint16
constexpr MetroProField kHeaderSize{"header_size", 6};           // uint32
constexpr MetroProField kAcWidth{"ac_width", 52};                // uint16, intensity columns
constexpr MetroProField kAcHeight{"ac_height", 54};              // uint16, intensity rows
constexpr MetroProField kAcBuckets{"ac_n_buckets", 56};          // uint16, intensity frames
constexpr MetroProField kCnWidth{"cn_width", 68};                // uint16, phase columns
constexpr MetroProField kCnHeight{"cn_height", 70};              // uint16, phase rows
constexpr MetroProField kScaleFactor{"intf_scale_factor", 164};  // float32
constexpr MetroProField kWavelength{"wavelength_in", 168};       // float32, m
constexpr MetroProField kObliquity{"obliquity_factor", 176};     // float32
constexpr MetroProField kLateralRes{"lateral_res", 184};         // float32, m/pixel (camera_res)
constexpr MetroProField kPhaseRes{"phase_res", 218};             // uint16: 0, 1, 2
constexpr MetroProField kSign{"sign", 232};                      // uint16, != 0: data inverted

// Phase codes from 0x7FFFFFF8 up mark pixels without data.
constexpr std::int32_t kInvalidPhase = 2147483640;

struct HeaderFormat {
  std::uint32_t magic;
  std::uint16_t format;
  std::uint32_t header_size;
};
constexpr std::array<HeaderFormat, 3> kHeaderFormats = {
    {{0x881B036F, 1, 834}, {0x881B0370, 2, 834}, {0x881B0371, 3, 4096}}};

class BigEndian {
 public:
  BigEndian(std::span<const unsigned char> bytes, const std::string& name) : bytes_(bytes), name_(name) {}
  [[nodiscard]] std::uint32_t U32(const MetroProField& f) const {
    return static_cast<std::uint32_t>(Get(f, 4));
  }
  [[nodiscard]] std::uint16_t U16(const MetroProField& f) const {
    return static_cast<std::uint16_t>(Get(f, 2));
  }
  [[nodiscard]] double F32(const MetroProField& f) const {
    const auto bits = static_cast<std::uint32_t>(Get(f, 4));
    float value = 0.0f;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }
  [[nodiscard]] std::int32_t I32At(std::size_t offset) const {
    const auto bits = static_cast<std::uint32_t>(Get({"phase data", offset}, 4));
    std::int32_t value = 0;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }

 private:
  [[nodiscard]] std::uint64_t Get(const MetroProField& f, std::size_t width) const {
    if (f.offset > bytes_.size() || bytes_.size() - f.offset < width) {
      Fail(name_, fmt::format("MetroPro field '{}' at byte {} lies beyond the {}-byte file (truncated?)",
                              f.name, f.offset, bytes_.size()));
    }
    std::uint64_t v = 0;
    for (std::size_t k = 0; k < width; ++k) v = (v << 8) | bytes_[f.offset + k];
    return v;
  }
  std::span<const unsigned char> bytes_;
  const std::string& name_;
};

void FieldFail(const std::string& name, const MetroProField& f, const std::string& what) {
  Fail(name, fmt::format("MetroPro field '{}' {}", f.name, what));
}

double PositiveFinite(const BigEndian& in, const MetroProField& f, const std::string& name) {
  const double v = in.F32(f);
  if (!std::isfinite(v) || v == 0.0) FieldFail(name, f, fmt::format("= {} must be finite and non-zero", v));
  return v;
}

std::vector<unsigned char> ReadBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, kStage, fmt::format("cannot open '{}'", path.string()));
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(ErrorCode::kIo, kStage, fmt::format("cannot read '{}'", path.string()));
  return bytes;
}

}  // namespace

PixelMap ParseMetroProDat(std::span<const unsigned char> bytes, const std::string& name) {
  const BigEndian in(bytes, name);
  const std::uint32_t magic = in.U32(kMagic);
  const auto format = std::find_if(kHeaderFormats.begin(), kHeaderFormats.end(),
                                   [&](const HeaderFormat& f) { return f.magic == magic; });
  if (format == kHeaderFormats.end()) {
    FieldFail(
        name, kMagic,
        fmt::format("= 0x{:08X} is not a MetroPro .dat magic number (0x881B036F, 0x881B0370, 0x881B0371)",
                    magic));
  }
  const std::uint16_t header_format = in.U16(kHeaderFormat);
  if (header_format != format->format) {
    FieldFail(name, kHeaderFormat,
              fmt::format("= {} does not match magic number 0x{:08X} (format {})", header_format, magic,
                          format->format));
  }
  const std::uint32_t header_size = in.U32(kHeaderSize);
  if (header_size != format->header_size) {
    FieldFail(name, kHeaderSize,
              fmt::format("= {} is not the {} bytes of header format {}", header_size, format->header_size,
                          format->format));
  }
  if (header_size > bytes.size()) {
    FieldFail(name, kHeaderSize,
              fmt::format("= {} bytes lies beyond the {}-byte file (truncated?)", header_size, bytes.size()));
  }
  // Sizes in 64 bits: three 16-bit factors cannot overflow.
  const std::uint64_t intensity_bytes = 2ull * in.U16(kAcWidth) * in.U16(kAcHeight) * in.U16(kAcBuckets);
  const std::uint64_t phase_offset = header_size + intensity_bytes;
  if (phase_offset > bytes.size()) {
    Fail(name, fmt::format("MetroPro fields 'ac_width' x 'ac_height' x 'ac_n_buckets' = {} x {} x {} declare "
                           "{} intensity bytes "
                           "after the {}-byte header, beyond the {}-byte file (truncated?)",
                           in.U16(kAcWidth), in.U16(kAcHeight), in.U16(kAcBuckets), intensity_bytes,
                           header_size, bytes.size()));
  }
  PixelMap map;
  map.width = in.U16(kCnWidth);
  map.height = in.U16(kCnHeight);
  if (map.width == 0 || map.height == 0) {
    Fail(name, fmt::format("MetroPro fields 'cn_width' x 'cn_height' = {} x {}: the file holds no phase data",
                           map.width, map.height));
  }
  const std::uint64_t phase_bytes =
      4ull * static_cast<std::uint64_t>(map.width) * static_cast<std::uint64_t>(map.height);
  if (bytes.size() - phase_offset < phase_bytes) {
    Fail(name,
         fmt::format(
             "MetroPro fields 'cn_width' x 'cn_height' = {} x {} declare {} phase bytes from byte {}, beyond "
             "the {}-byte file (truncated?)",
             map.width, map.height, phase_bytes, phase_offset, bytes.size()));
  }
  CheckMapNodes(name, "phase data 'cn_height' x 'cn_width'", map.height, map.width);
  const std::uint16_t phase_res = in.U16(kPhaseRes);
  static constexpr std::array<double, 3> kResolution = {4096.0, 32768.0, 131072.0};
  if (phase_res >= kResolution.size())
    FieldFail(name, kPhaseRes, fmt::format("= {} is not 0, 1 or 2", phase_res));
  const double wavelength_m = in.F32(kWavelength);
  if (!(wavelength_m > 0.0 && std::isfinite(wavelength_m)))
    FieldFail(name, kWavelength, fmt::format("= {} m must be > 0", wavelength_m));
  double um_per_count = 1e6 * PositiveFinite(in, kScaleFactor, name) * PositiveFinite(in, kObliquity, name) *
                        wavelength_m / kResolution[phase_res];
  if (in.U16(kSign) != 0) um_per_count = -um_per_count;
  const double lateral_m = in.F32(kLateralRes);
  if (lateral_m > 0.0 && std::isfinite(lateral_m)) map.pixel_x_mm = map.pixel_y_mm = lateral_m * 1e3;
  map.height_um.resize(static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height));
  for (std::size_t k = 0; k < map.height_um.size(); ++k) {
    const std::int32_t code = in.I32At(static_cast<std::size_t>(phase_offset) + 4 * k);
    map.height_um[k] = code >= kInvalidPhase ? kNaN : um_per_count * code;
  }
  return map;
}

PixelMap ReadMetroProDat(const std::filesystem::path& path) {
  const std::vector<unsigned char> bytes = ReadBytes(path);
  return ParseMetroProDat(bytes, path.string());
}

}  // namespace arcwheel::polishing
