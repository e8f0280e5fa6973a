#include "polishing/error_map_io.h"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "core/nan.h"
#include "core/testing/testing.h"
#include "polishing/job.h"

namespace arcwheel::polishing {
namespace {

using arcwheel::testing::ErrorMessageOf;
using arcwheel::testing::WriteText;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The grid placement of `map` (size, origin, spacing) against `expected`'s, exactly: the
// readers copy these numbers, or take them as differences of numbers exact in binary.
void ExpectPlacement(const ErrorMap& map, const ErrorMap& expected) {
  EXPECT_EQ(map.grid.nx, expected.grid.nx);
  EXPECT_EQ(map.grid.ny, expected.grid.ny);
  EXPECT_EQ(map.grid.x0_mm, expected.grid.x0_mm);
  EXPECT_EQ(map.grid.y0_mm, expected.grid.y0_mm);
  EXPECT_EQ(map.grid.dx_mm, expected.grid.dx_mm);
  EXPECT_EQ(map.grid.dy_mm, expected.grid.dy_mm);
}

// ------------------------------------------------------------------------------------------------
// Map CSV (formerly in job_test.cc, which now tests the job reader).

std::string CsvError(const std::string& text) {
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "map.csv") << text;
  return ErrorMessageOf([&dir] { (void)ReadErrorMapCsv(dir / "map.csv"); });
}

TEST(ReadErrorMapCsv, PlacesScatteredRowsOnTheirGridAndLeavesGapsWithoutData) {
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "map.csv")
      << "# comment\nx_mm,y_mm,error_um\n2.5,-1,0.25\n-2.5,-1,1\n0,1,nan\n2.5,1,-3\n";
  const ErrorMap map = ReadErrorMapCsv(dir / "map.csv");
  ExpectPlacement(map, {.grid = {.x0_mm = -2.5, .y0_mm = -1.0, .dx_mm = 2.5, .dy_mm = 2.0, .nx = 3, .ny = 2},
                        .error_um = {}});
  EXPECT_DOUBLE_EQ(map.At(0, 0), 1.0);
  EXPECT_TRUE(std::isnan(map.At(1, 0)));  // never given
  EXPECT_DOUBLE_EQ(map.At(2, 0), 0.25);
  EXPECT_TRUE(std::isnan(map.At(1, 1)));  // given as nan
  EXPECT_DOUBLE_EQ(map.At(2, 1), -3.0);
}

TEST(ReadErrorMapCsv, NamesTheFileAndLineOfMalformedInput) {
  EXPECT_NE(CsvError("x,y,z\n").find("map.csv' line 1: header 'x,y,z'"), std::string::npos);
  EXPECT_NE(CsvError("x_mm,y_mm,error_um\n0,0,1\n1,0,abc\n").find("line 3: 'abc' is not a number"),
            std::string::npos);
  EXPECT_NE(CsvError("x_mm,y_mm,error_um\n0,0,1\n1,0\n").find("line 3: has 2 values"), std::string::npos);
  EXPECT_NE(CsvError("x_mm,y_mm,error_um\n0,0,1\n1,0,2\n2,0,2\n3,0,2\n3.4,0,3\n")
                .find("line 6: (3.4, 0) mm is not on the regular grid"),
            std::string::npos);
  EXPECT_NE(CsvError("x_mm,y_mm,error_um\n0,0,1\n1,0,2\n1,0,3\n").find("line 4: (1, 0) mm appears twice"),
            std::string::npos);
}

TEST(ReadErrorMapCsv, RefusesAnInfinityNamingTheLineButReadsNanAsNoData) {
  for (const char* infinity : {"inf", "-inf", "Infinity", "1e999"}) {
    const std::string message =
        CsvError(std::string("x_mm,y_mm,error_um\n0,0,nan\n1,0,") + infinity + "\n2,0,1\n");
    EXPECT_NE(message.find("map.csv' line 3: error_um = "), std::string::npos) << message;
    EXPECT_NE(message.find("is not finite"), std::string::npos) << message;
  }
}

// ------------------------------------------------------------------------------------------------
// An independent MetroPro writer: the header fields at the byte offsets of the MetroPro Reference
// Guide (OMP-0347, appendix B), big-endian by hand.
struct DatSpec {
  int header_format = 1;      // 1, 2, 3
  int width = 7, height = 5;  // phase pixels (cn_width, cn_height)
  int intensity_width = 3, intensity_height = 2, buckets = 1;
  int phase_res = 1;
  float scale_factor = 0.5f, obliquity = 1.0f, wavelength_m = 632.8e-9f, lateral_res_m = 1.25e-4f;
  int sign = 0;
  std::function<double(int, int)> height_m;  // NaN = no data
};

void PutBe(std::vector<unsigned char>& b, std::size_t offset, std::uint64_t value, int bytes) {
  for (int k = 0; k < bytes; ++k) b[offset + k] = static_cast<unsigned char>(value >> (8 * (bytes - 1 - k)));
}
void PutF32(std::vector<unsigned char>& b, std::size_t offset, float value) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, 4);
  PutBe(b, offset, bits, 4);
}

double Resolution(int phase_res) { return phase_res == 0 ? 4096.0 : phase_res == 1 ? 32768.0 : 131072.0; }
// Metres per phase count, with the header's float32 values.
double StepM(const DatSpec& s) {
  return static_cast<double>(s.scale_factor) * s.obliquity * s.wavelength_m / Resolution(s.phase_res);
}

std::vector<unsigned char> MetroProImage(const DatSpec& s) {
  const std::uint32_t magic[] = {0x881B036F, 0x881B0370, 0x881B0371};
  const std::size_t header = s.header_format == 3 ? 4096 : 834;
  const std::size_t intensity = 2u * s.intensity_width * s.intensity_height * s.buckets;
  std::vector<unsigned char> b(header + intensity + 4u * s.width * s.height, 0);
  PutBe(b, 0, magic[s.header_format - 1], 4);
  PutBe(b, 4, static_cast<std::uint64_t>(s.header_format), 2);
  PutBe(b, 6, header, 4);
  PutBe(b, 52, static_cast<std::uint64_t>(s.intensity_width), 2);
  PutBe(b, 54, static_cast<std::uint64_t>(s.intensity_height), 2);
  PutBe(b, 56, static_cast<std::uint64_t>(s.buckets), 2);
  PutBe(b, 60, intensity, 4);
  PutBe(b, 68, static_cast<std::uint64_t>(s.width), 2);
  PutBe(b, 70, static_cast<std::uint64_t>(s.height), 2);
  PutBe(b, 72, 4u * s.width * s.height, 4);
  PutF32(b, 164, s.scale_factor);
  PutF32(b, 168, s.wavelength_m);
  PutF32(b, 176, s.obliquity);
  PutF32(b, 184, s.lateral_res_m);
  PutBe(b, 218, static_cast<std::uint64_t>(s.phase_res), 2);
  PutBe(b, 232, static_cast<std::uint64_t>(s.sign), 2);
  // Intensity: a marker pattern a reader that skipped the block wrongly would take for phase.
  for (std::size_t k = 0; k < intensity; k += 2) PutBe(b, header + k, 0x1234, 2);
  std::size_t at = header + intensity;
  int invalid = 0;
  for (int j = 0; j < s.height; ++j) {
    for (int i = 0; i < s.width; ++i, at += 4) {
      const double h = s.height_m(i, j);
      // Any code from 0x7FFFFFF8 up is invalid: use several.
      const std::int64_t code = std::isnan(h) ? 2147483640 + (invalid++ % 8) : std::llround(h / StepM(s));
      PutBe(b, at, static_cast<std::uint32_t>(static_cast<std::int32_t>(code)), 4);
    }
  }
  return b;
}

// A tilted, curved height map with a few pixels without data, in metres.
double TestHeightM(int i, int j) {
  if ((i == 0 && j == 0) || (i == 3 && j == 2) || (i == 6 && j == 4)) return kNaN;
  return 1e-9 * (40.0 * i - 25.0 * j + 3.0 * i * j - 60.0);
}

// A MetroPro .dat file of the default DatSpec with TestHeightM's heights.
std::vector<unsigned char> TestMetroProImage() {
  DatSpec spec;
  spec.height_m = TestHeightM;
  return MetroProImage(spec);
}

TEST(ParseMetroProDat, RecoversHeightsToTheQuantisationStepInEveryHeaderFormatAndPhaseResolution) {
  for (const int format : {1, 2, 3}) {
    for (const int phase_res : {0, 1, 2}) {
      DatSpec spec;
      spec.header_format = format;
      spec.phase_res = phase_res;
      spec.height_m = TestHeightM;
      const PixelMap map = ParseMetroProDat(MetroProImage(spec), "part.dat");
      ASSERT_EQ(map.width, spec.width);
      ASSERT_EQ(map.height, spec.height);
      EXPECT_DOUBLE_EQ(map.pixel_x_mm, static_cast<double>(spec.lateral_res_m) * 1e3);
      EXPECT_DOUBLE_EQ(map.pixel_y_mm, static_cast<double>(spec.lateral_res_m) * 1e3);
      const double half_step_um = 0.5 * StepM(spec) * 1e6 * (1.0 + 1e-9);
      for (int j = 0; j < spec.height; ++j) {
        for (int i = 0; i < spec.width; ++i) {
          const double truth_um = TestHeightM(i, j) * 1e6;
          const double read_um = map.height_um[static_cast<std::size_t>(j) * spec.width + i];
          if (std::isnan(truth_um)) {
            EXPECT_TRUE(std::isnan(read_um)) << "format " << format << " pixel " << i << "," << j;
          } else {
            EXPECT_NEAR(read_um, truth_um, half_step_um) << "format " << format << " phase_res " << phase_res;
          }
        }
      }
    }
  }
}

TEST(ParseMetroProDat, NegatesHeightsWhenTheSignFlagIsSet) {
  DatSpec spec;
  spec.height_m = [](int i, int) { return 1e-8 * (i + 1); };
  const PixelMap plain = ParseMetroProDat(MetroProImage(spec), "a.dat");
  spec.sign = 1;
  const PixelMap inverted = ParseMetroProDat(MetroProImage(spec), "a.dat");
  for (std::size_t k = 0; k < plain.height_um.size(); ++k)
    EXPECT_EQ(inverted.height_um[k], -plain.height_um[k]);
}

TEST(PlaceInPartFrame, PutsEachPixelAtItsLateralPositionWithRowsRunningDownTheCamera) {
  DatSpec spec;
  spec.height_m = TestHeightM;
  const PixelMap pixels = ParseMetroProDat(MetroProImage(spec), "part.dat");
  const ErrorMap map = PlaceInPartFrame(pixels, {}, "part.dat");
  const double p = static_cast<double>(spec.lateral_res_m) * 1e3;
  // Valid data span all columns 0..6 and rows 0..4: the centre pixel (3, 2) lands on the origin.
  EXPECT_EQ(map.grid.nx, 7);
  EXPECT_EQ(map.grid.ny, 5);
  EXPECT_DOUBLE_EQ(map.grid.dx_mm, p);
  for (int j = 0; j < spec.height; ++j) {
    for (int i = 0; i < spec.width; ++i) {
      const double x = (i - 3) * p, y = (2 - j) * p;  // row 0 is the top: highest y
      const int I = static_cast<int>(std::lround((x - map.grid.x0_mm) / map.grid.dx_mm));
      const int J = static_cast<int>(std::lround((y - map.grid.y0_mm) / map.grid.dy_mm));
      ASSERT_NEAR(map.grid.X(I), x, 1e-12);
      ASSERT_NEAR(map.grid.Y(J), y, 1e-12);
      const double expected = pixels.height_um[static_cast<std::size_t>(j) * spec.width + i];
      if (std::isnan(expected)) {
        EXPECT_TRUE(std::isnan(map.At(I, J)));
      } else {
        EXPECT_EQ(map.At(I, J), expected);
      }
    }
  }
}

TEST(PlaceInPartFrame, RotatesFlipsScalesAndTranslatesAsTheRigidMotionItNames) {
  PixelMap pixels;
  pixels.width = 4;
  pixels.height = 3;
  pixels.pixel_x_mm = pixels.pixel_y_mm = 0.5;
  for (int k = 0; k < 12; ++k) pixels.height_um.push_back(k + 1.0);
  for (const int rotation : {0, 90, 180, 270}) {
    for (const auto flip : {MapPlacement::Flip::kNone, MapPlacement::Flip::kX, MapPlacement::Flip::kY}) {
      MapPlacement placement{.centre_column = 1.0,
                             .centre_row = 2.0,
                             .centre_x_mm = 10.0,
                             .centre_y_mm = -4.0,
                             .rotation_deg = rotation,
                             .flip = flip,
                             .scale = -2.0};
      const ErrorMap map = PlaceInPartFrame(pixels, placement, "m.dat");
      const double a = rotation * M_PI / 180.0;
      for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 4; ++i) {
          double u = (i - 1.0) * 0.5, v = (2.0 - j) * 0.5;
          if (flip == MapPlacement::Flip::kX) u = -u;
          if (flip == MapPlacement::Flip::kY) v = -v;
          const double x = std::cos(a) * u - std::sin(a) * v + 10.0,
                       y = std::sin(a) * u + std::cos(a) * v - 4.0;
          const int I = static_cast<int>(std::lround((x - map.grid.x0_mm) / map.grid.dx_mm));
          const int J = static_cast<int>(std::lround((y - map.grid.y0_mm) / map.grid.dy_mm));
          ASSERT_TRUE(I >= 0 && I < map.grid.nx && J >= 0 && J < map.grid.ny);
          EXPECT_NEAR(map.grid.X(I), x, 1e-12);
          EXPECT_NEAR(map.grid.Y(J), y, 1e-12);
          EXPECT_EQ(map.At(I, J), -2.0 * (j * 4 + i + 1.0)) << rotation << " deg";
        }
      }
    }
  }
}

TEST(PlaceInPartFrame, NeedsALateralResolutionFromTheFileOrTheJob) {
  DatSpec spec;
  spec.lateral_res_m = 0.0f;
  spec.height_m = TestHeightM;
  const PixelMap pixels = ParseMetroProDat(MetroProImage(spec), "nores.dat");
  EXPECT_TRUE(std::isnan(pixels.pixel_x_mm));
  const std::string message = ErrorMessageOf([&] { (void)PlaceInPartFrame(pixels, {}, "nores.dat"); });
  EXPECT_TRUE(Contains(message, "'nores.dat'") && Contains(message, "pixel_mm")) << message;
  const ErrorMap map = PlaceInPartFrame(pixels, {.pixel_mm = 0.2}, "nores.dat");
  EXPECT_DOUBLE_EQ(map.grid.dx_mm, 0.2);
}

TEST(ParseMetroProDat, RefusesCorruptHeadersNamingTheFileAndTheField) {
  DatSpec spec;
  spec.height_m = TestHeightM;
  const std::vector<unsigned char> good = MetroProImage(spec);
  auto error = [](std::vector<unsigned char> bytes) {
    return ErrorMessageOf([&] { (void)ParseMetroProDat(bytes, "bad.dat"); });
  };
  std::vector<unsigned char> b = good;
  b[3] = 0x00;
  EXPECT_TRUE(Contains(error(b), "'bad.dat'") && Contains(error(b), "magic_number")) << error(b);
  EXPECT_TRUE(Contains(error({good.begin(), good.end() - 1}), "'cn_width' x 'cn_height'"))
      << error({good.begin(), good.end() - 1});
  EXPECT_TRUE(Contains(error({good.begin(), good.begin() + 500}), "header_size"))
      << error({good.begin(), good.begin() + 500});
  EXPECT_TRUE(Contains(error({good.begin(), good.begin() + 5}), "header_format"))
      << error({good.begin(), good.begin() + 5});
  b = good;
  PutBe(b, 4, 3, 2);  // format 3 with the format-1 magic
  EXPECT_TRUE(Contains(error(b), "header_format")) << error(b);
  b = good;
  PutBe(b, 6, 4096, 4);
  EXPECT_TRUE(Contains(error(b), "header_size")) << error(b);
  b = good;
  PutBe(b, 56, 60000, 2);  // intensity buckets far beyond the file
  EXPECT_TRUE(Contains(error(b), "ac_n_buckets")) << error(b);
  b = good;
  PutBe(b, 68, 65535, 2);
  PutBe(b, 70, 65535, 2);
  EXPECT_TRUE(Contains(error(b), "'cn_width' x 'cn_height' = 65535 x 65535")) << error(b);
  b = good;
  PutBe(b, 218, 7, 2);
  EXPECT_TRUE(Contains(error(b), "phase_res")) << error(b);
  b = good;
  PutF32(b, 168, std::numeric_limits<float>::quiet_NaN());
  EXPECT_TRUE(Contains(error(b), "wavelength_in")) << error(b);
  // Every prefix of a valid file is refused cleanly (the sanitizer build checks the reads).
  for (std::size_t n = 0; n < good.size(); ++n) {
    EXPECT_NE(error({good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n)}), "accepted") << n;
  }
}

// ------------------------------------------------------------------------------------------------
// Zygo Mx .datx written with the HDF5 C API: /Measurement/Surface with its converters.
struct DatxSpec {
  bool with_surface = true;
  bool variable_length = true;  // converter strings and parameters variable-length, else fixed
  std::string z_unit = "NanoMeters";
  double lateral_m = 2.5e-5;
  double no_data = std::numeric_limits<double>::max();
};

void WriteConverter(hid_t dataset, const char* name, const DatxSpec& spec, const std::string& category,
                    const std::string& unit, const std::vector<double>& parameters) {
  hid_t type = -1, string_type = H5Tcopy(H5T_C_S1), numbers_type = -1;
  std::vector<unsigned char> buffer;
  if (spec.variable_length) {
    struct Converter {
      const char* category;
      const char* unit;
      hvl_t parameters;
    };
    H5Tset_size(string_type, H5T_VARIABLE);
    numbers_type = H5Tvlen_create(H5T_NATIVE_DOUBLE);
    type = H5Tcreate(H5T_COMPOUND, sizeof(Converter));
    H5Tinsert(type, "Category", HOFFSET(Converter, category), string_type);
    H5Tinsert(type, "BaseUnit", HOFFSET(Converter, unit), string_type);
    H5Tinsert(type, "Parameters", HOFFSET(Converter, parameters), numbers_type);
    const Converter value{
        category.c_str(), unit.c_str(), {parameters.size(), const_cast<double*>(parameters.data())}};
    buffer.resize(sizeof value);
    std::memcpy(buffer.data(), &value, sizeof value);
  } else {
    struct Converter {
      char category[16];
      char unit[16];
      double parameters[4];
    };
    H5Tset_size(string_type, 16);
    const hsize_t four = 4;
    numbers_type = H5Tarray_create2(H5T_NATIVE_DOUBLE, 1, &four);
    type = H5Tcreate(H5T_COMPOUND, sizeof(Converter));
    H5Tinsert(type, "Category", HOFFSET(Converter, category), string_type);
    H5Tinsert(type, "BaseUnit", HOFFSET(Converter, unit), string_type);
    H5Tinsert(type, "Parameters", HOFFSET(Converter, parameters), numbers_type);
    Converter value{};
    std::strncpy(value.category, category.c_str(), 15);
    std::strncpy(value.unit, unit.c_str(), 15);
    for (std::size_t k = 0; k < 4 && k < parameters.size(); ++k) value.parameters[k] = parameters[k];
    buffer.resize(sizeof value);
    std::memcpy(buffer.data(), &value, sizeof value);
  }
  const hsize_t one = 1;
  const hid_t space = H5Screate_simple(1, &one, nullptr);
  const hid_t attribute = H5Acreate2(dataset, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(H5Awrite(attribute, type, buffer.data()), 0);
  H5Aclose(attribute);
  H5Sclose(space);
  H5Tclose(type);
  H5Tclose(numbers_type);
  H5Tclose(string_type);
}

void WriteDoublesAttribute(hid_t object, const char* name, double value) {
  const hsize_t one = 1;
  const hid_t space = H5Screate_simple(1, &one, nullptr);
  const hid_t attribute = H5Acreate2(object, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attribute, H5T_NATIVE_DOUBLE, &value);
  H5Aclose(attribute);
  H5Sclose(space);
}

// heights_in_unit[j][i]; NaN is written as the No Data value.
void WriteDatx(const std::filesystem::path& path, const DatxSpec& spec, int width, int height,
               const std::function<double(int, int)>& heights_in_unit) {
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const hid_t group = H5Gcreate2(file, "Measurement", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (spec.with_surface) {
    const hsize_t dims[2] = {static_cast<hsize_t>(height), static_cast<hsize_t>(width)};
    const hid_t space = H5Screate_simple(2, dims, nullptr);
    const hid_t dataset =
        H5Dcreate2(group, "Surface", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    std::vector<double> values;
    for (int j = 0; j < height; ++j) {
      for (int i = 0; i < width; ++i)
        values.push_back(std::isnan(heights_in_unit(i, j)) ? spec.no_data : heights_in_unit(i, j));
    }
    H5Dwrite(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
    WriteDoublesAttribute(dataset, "No Data", spec.no_data);
    WriteConverter(dataset, "X Converter", spec, "LateralCat", "Meters", {0.0, spec.lateral_m, 0.0, 0.0});
    WriteConverter(dataset, "Y Converter", spec, "LateralCat", "Meters", {0.0, spec.lateral_m, 0.0, 0.0});
    WriteConverter(dataset, "Z Converter", spec, "HeightCat", spec.z_unit, {0.0, 632.8e-9, 0.5, 1.0});
    if (spec.z_unit == "Fringes") {
      WriteDoublesAttribute(dataset, "Wavelength", 632.8e-9);
      WriteDoublesAttribute(dataset, "Interferometric Scale Factor", 0.5);
      WriteDoublesAttribute(dataset, "Obliquity Factor", 1.0);
    }
    H5Dclose(dataset);
    H5Sclose(space);
  }
  H5Gclose(group);
  H5Fclose(file);
}

std::vector<unsigned char> FileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

double DatxHeightNm(int i, int j) { return (i == 2 && j == 1) ? kNaN : 12.5 * i - 7.25 * j + 0.5 * i * i; }

TEST(ReadZygoDatx, ReadsHeightsNoDataAndLateralResolutionFromAnInMemoryImage) {
  for (const bool variable_length : {true, false}) {
    arcwheel::testing::TempDir dir;
    DatxSpec spec;
    spec.variable_length = variable_length;
    WriteDatx(dir / "part.datx", spec, 6, 4, DatxHeightNm);
    const std::vector<unsigned char> bytes = FileBytes(dir / "part.datx");
    const PixelMap map = ReadZygoDatx(hdf5::File::OpenImage(bytes.data(), bytes.size(), "part.datx"));
    ASSERT_EQ(map.width, 6);
    ASSERT_EQ(map.height, 4);
    EXPECT_DOUBLE_EQ(map.pixel_x_mm, 0.025);
    EXPECT_DOUBLE_EQ(map.pixel_y_mm, 0.025);
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 6; ++i) {
        const double read = map.height_um[static_cast<std::size_t>(j) * 6 + i];
        if (std::isnan(DatxHeightNm(i, j))) {
          EXPECT_TRUE(std::isnan(read));
        } else {
          EXPECT_NEAR(read, DatxHeightNm(i, j) * 1e-3, 1e-15);
        }
      }
    }
  }
}

TEST(ReadZygoDatx, ConvertsFringesWithWavelengthScaleAndObliquity) {
  arcwheel::testing::TempDir dir;
  DatxSpec spec;
  spec.z_unit = "Fringes";
  WriteDatx(dir / "f.datx", spec, 3, 2, [](int i, int j) { return 0.1 * i + 0.01 * j; });
  const PixelMap map = ReadZygoDatx(dir / "f.datx");
  // One fringe = 632.8 nm * 0.5 * 1.0 of height.
  EXPECT_NEAR(map.height_um[4], (0.1 + 0.01) * 0.3164, 1e-12);
}

TEST(ReadZygoDatx, RefusesAFileWithoutTheSurfaceDatasetOrAHeightUnit) {
  arcwheel::testing::TempDir dir;
  DatxSpec spec;
  spec.with_surface = false;
  WriteDatx(dir / "empty.datx", spec, 3, 2, DatxHeightNm);
  std::string message = ErrorMessageOf([&] { (void)ReadZygoDatx(dir / "empty.datx"); });
  EXPECT_TRUE(Contains(message, "empty.datx'") && Contains(message, "/Measurement/Surface")) << message;
  spec.with_surface = true;
  spec.z_unit = "Volts";
  WriteDatx(dir / "volts.datx", spec, 3, 2, DatxHeightNm);
  message = ErrorMessageOf([&] { (void)ReadZygoDatx(dir / "volts.datx"); });
  EXPECT_TRUE(Contains(message, "volts.datx'") && Contains(message, "Z Converter") &&
              Contains(message, "Volts"))
      << message;
}

// .datx files as h5py writes them in the layouts instruments use (tests/foreign/write_datx.py):
// MetroPro's /Data/Surface/{GUID} found through /MetaData, /Measurement/Surface, and a lone
// dataset under /Data/Surface. The script computes every height itself from what it wrote.
class DatxLayouts : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<arcwheel::testing::TempDir>();
    const std::string command =
        "/usr/bin/python3 " + (arcwheel::testing::SourceDir() / "tests/foreign/write_datx.py").string() +
        " " + dir_->path().string() + " > " + (*dir_ / "writer.log").string() + " 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << command << "\n"
                                               << arcwheel::testing::ReadText(*dir_ / "writer.log");
    expected_ = nlohmann::json::parse(arcwheel::testing::ReadText(*dir_ / "expected.json"));
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::unique_ptr<arcwheel::testing::TempDir> dir_;
  static nlohmann::json expected_;
};
std::unique_ptr<arcwheel::testing::TempDir> DatxLayouts::dir_;
nlohmann::json DatxLayouts::expected_;

// Valid pixels, PV and RMS about the mean of a pixel map, in the map's unit.
struct PixelFigures {
  std::size_t valid = 0;
  double pv = 0.0;
  double rms = 0.0;
};
PixelFigures FiguresOf(const std::vector<double>& heights) {
  std::vector<double> valid;
  std::copy_if(heights.begin(), heights.end(), std::back_inserter(valid),
               [](double h) { return !std::isnan(h); });
  PixelFigures f{.valid = valid.size()};
  if (valid.empty()) return f;
  const auto [low, high] = std::minmax_element(valid.begin(), valid.end());
  f.pv = *high - *low;
  double mean = 0.0, square = 0.0;
  for (const double h : valid) mean += h / static_cast<double>(valid.size());
  for (const double h : valid) square += (h - mean) * (h - mean) / static_cast<double>(valid.size());
  f.rms = std::sqrt(square);
  return f;
}

TEST_F(DatxLayouts, ReadsEveryLayoutToThePixelsTheWriterComputed) {
  for (const auto& [file, want] : expected_["good"].items()) {
    SCOPED_TRACE(file);
    const PixelMap map = ReadZygoDatx(*dir_ / "good" / file);
    ASSERT_EQ(map.width, want["width"].get<int>());
    ASSERT_EQ(map.height, want["height"].get<int>());
    EXPECT_DOUBLE_EQ(map.pixel_x_mm, want["pixel_mm"].get<double>());
    EXPECT_DOUBLE_EQ(map.pixel_y_mm, want["pixel_mm"].get<double>());
    for (int j = 0; j < map.height; ++j) {
      for (int i = 0; i < map.width; ++i) {
        const nlohmann::json& h = want["height_um"][j][i];
        const double read = map.height_um[static_cast<std::size_t>(j) * map.width + i];
        if (h.is_null()) {
          EXPECT_TRUE(std::isnan(read)) << "[" << j << "][" << i << "]";
        } else {
          // The same product in another order: a few units in the last place.
          EXPECT_NEAR(read, h.get<double>(), 1e-14 * std::abs(h.get<double>()))
              << "[" << j << "][" << i << "]";
        }
      }
    }
    const PixelFigures figures = FiguresOf(map.height_um);
    EXPECT_EQ(figures.valid, want["valid_pixels"].get<std::size_t>());
    EXPECT_NEAR(figures.pv, want["pv_um"].get<double>(), 1e-13);
    EXPECT_NEAR(figures.rms, want["rms_um"].get<double>(), 1e-13);
  }
}

TEST_F(DatxLayouts, RefusesAnAmbiguousOrMissingSurfaceAndAnInfinityNamingTheFile) {
  ASSERT_FALSE(expected_["bad"].empty());
  for (const auto& [file, reason] : expected_["bad"].items()) {
    const std::string message =
        ErrorMessageOf([&, name = file] { (void)ReadZygoDatx(*dir_ / "bad" / name); });
    EXPECT_TRUE(Contains(message, file + "'") && Contains(message, reason.get<std::string>()))
        << file << ": " << message;
  }
}

// Real instrument files from public repositories (not part of the project: they are third-party
// data). With ARCWHEEL_ZYGO_REAL_DIR set to a folder holding them, each must read to the figures
// that its source project's own reader gives (valid pixels, PV nm, RMS nm about the mean; the
// figures are given to 1e-6 nm).
TEST(RealZygoFiles, ReadToTheirSourceProjectsFigures) {
  const char* folder = std::getenv("ARCWHEEL_ZYGO_REAL_DIR");
  if (folder == nullptr) GTEST_SKIP() << "set ARCWHEEL_ZYGO_REAL_DIR to the folder of the real Zygo files";
  struct Real {
    const char* file;
    std::size_t valid;
    double pv_nm, rms_nm;
  };
  for (const Real& real : {Real{"prysm_valid_zygo_dat_file.dat", 136359, 330.700173, 44.591409},
                           Real{"surftopo_metropro-1.dat", 307200, 1363.056329, 75.288222},
                           Real{"monolithic_zygo_test.datx", 7771, 453.030479, 80.817653}}) {
    const std::filesystem::path path = std::filesystem::path(folder) / real.file;
    const PixelMap map = path.extension() == ".datx" ? ReadZygoDatx(path) : ReadMetroProDat(path);
    const PixelFigures figures = FiguresOf(map.height_um);
    EXPECT_EQ(figures.valid, real.valid) << real.file;
    EXPECT_NEAR(figures.pv * 1e3, real.pv_nm, 1e-6) << real.file;
    EXPECT_NEAR(figures.rms * 1e3, real.rms_nm, 1e-6) << real.file;
    std::printf("%s: %zu valid pixels, PV %.6f nm, RMS %.6f nm\n", real.file, figures.valid, figures.pv * 1e3,
                figures.rms * 1e3);
  }
}

// libhdf5 1.10 steps through a global heap collection by each object's size and never returns from
// a zero-size object. Zeroing the body of the collection that holds the converters' strings makes
// its first object exactly that; the reader must refuse the file instead of handing it on.
TEST(ReadZygoDatx, RefusesAGlobalHeapThatWouldHangTheLibrary) {
  arcwheel::testing::TempDir dir;
  WriteDatx(dir / "part.datx", DatxSpec{}, 6, 4, DatxHeightNm);
  std::vector<unsigned char> bytes = FileBytes(dir / "part.datx");
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const std::size_t collection = text.find("GCOL");
  ASSERT_NE(collection, std::string_view::npos) << "variable-length converters live in a global heap";
  EXPECT_EQ(text.find("GCOL", collection + 1), std::string_view::npos);
  // Header: "GCOL", version, 3 reserved bytes, 8-byte collection size; objects follow at byte 16.
  std::uint64_t size = 0;
  std::memcpy(&size, &bytes[collection + 8], sizeof size);
  ASSERT_LE(collection + size, bytes.size());
  std::fill(bytes.begin() + static_cast<std::ptrdiff_t>(collection + 16),
            bytes.begin() + static_cast<std::ptrdiff_t>(collection + size), 0);
  const std::string message = ErrorMessageOf(
      [&] { (void)ReadZygoDatx(hdf5::File::OpenImage(bytes.data(), bytes.size(), "zeroed.datx")); });
  EXPECT_TRUE(Contains(message, "zeroed.datx'") &&
              Contains(message, "global heap at byte " + std::to_string(collection) + " is damaged"))
      << message;
}

// A global heap object is a 16-byte header (id: 2 bytes, references: 2, reserved: 4, size: 8)
// followed by its bytes. Corrupting the header of the object that holds the Z converter's
// "HeightCat" either orphans the reference (libhdf5 1.10.8 then reads through a null pointer) or
// makes the object longer than the reference (the library then overruns its buffer).
TEST(ReadZygoDatx, RefusesAReferenceToAMissingOrLongerHeapObject) {
  arcwheel::testing::TempDir dir;
  WriteDatx(dir / "part.datx", DatxSpec{}, 6, 4, DatxHeightNm);
  const std::vector<unsigned char> good = FileBytes(dir / "part.datx");
  const std::string_view text(reinterpret_cast<const char*>(good.data()), good.size());
  const std::size_t object = text.find("HeightCat") - 16;
  std::uint64_t size = 0;
  std::memcpy(&size, &good[object + 8], sizeof size);
  ASSERT_EQ(size, 9U) << "the header of the object holding \"HeightCat\"";

  std::vector<unsigned char> orphaned = good;
  orphaned[object] = 0xff;
  orphaned[object + 1] = 0x7f;
  std::string message = ErrorMessageOf(
      [&] { (void)ReadZygoDatx(hdf5::File::OpenImage(orphaned.data(), orphaned.size(), "orphaned.datx")); });
  EXPECT_TRUE(Contains(message, "orphaned.datx'") &&
              Contains(message, "'Category' of attribute 'Z Converter'") &&
              Contains(message, "which has none"))
      << message;

  std::vector<unsigned char> longer = good;
  longer[object + 8] = 15;  // same step through the collection: 15 and 9 both align to 16
  message = ErrorMessageOf(
      [&] { (void)ReadZygoDatx(hdf5::File::OpenImage(longer.data(), longer.size(), "longer.datx")); });
  EXPECT_TRUE(Contains(message, "longer.datx'") && Contains(message, "refers to 9 bytes") &&
              Contains(message, "which holds 15"))
      << message;
}

// ------------------------------------------------------------------------------------------------

TEST(ErrorMapHdf5, RoundTripsEveryNodeAndTheGridPlacement) {
  arcwheel::testing::TempDir dir;
  ErrorMap map{.grid = {.x0_mm = -12.5, .y0_mm = 3.0, .dx_mm = 0.25, .dy_mm = 0.5, .nx = 5, .ny = 3},
               .error_um = {}};
  for (int k = 0; k < 15; ++k) map.error_um.push_back(k == 7 ? kNaN : 0.1 * k - 0.3);
  WriteErrorMapHdf5(map, dir / "grid.h5");
  const ErrorMap read = ReadErrorMapHdf5(dir / "grid.h5");
  ExpectPlacement(read, map);
  for (std::size_t k = 0; k < 15; ++k) {
    if (k == 7) {
      EXPECT_TRUE(std::isnan(read.error_um[k]));
    } else {
      EXPECT_EQ(read.error_um[k], map.error_um[k]);
    }
  }
}

TEST(ErrorMapHdf5, RefusesAnInfinityNamingTheDatasetAndItsIndex) {
  arcwheel::testing::TempDir dir;
  ErrorMap map{.grid = {.nx = 4, .ny = 3}, .error_um = std::vector<double>(12, 0.5)};
  map.error_um[1] = kNaN;  // no data: read as such
  map.error_um[6] = -std::numeric_limits<double>::infinity();
  map.error_um[9] = std::numeric_limits<double>::infinity();
  WriteErrorMapHdf5(map, dir / "inf.h5");
  const std::string message = ErrorMessageOf([&] { (void)ReadErrorMapHdf5(dir / "inf.h5"); });
  EXPECT_TRUE(Contains(message, "inf.h5'") && Contains(message, "dataset 'error_um' value [1][2] = -inf") &&
              Contains(message, "not finite"))
      << message;
}

TEST(ErrorMapHdf5, RefusesAMissingAttributeOrDatasetByName) {
  arcwheel::testing::TempDir dir;
  {
    hdf5::File file = hdf5::File::Create(dir / "noattr.h5");
    file.WriteDoubles("/error_um", {1.0, 2.0}, {1, 2});
    file.WriteAttribute("/", "x0_mm", 0.0);
    file.WriteAttribute("/", "y0_mm", 0.0);
    file.WriteAttribute("/", "dx_mm", 1.0);
  }
  std::string message = ErrorMessageOf([&] { (void)ReadErrorMapHdf5(dir / "noattr.h5"); });
  EXPECT_TRUE(Contains(message, "noattr.h5'") && Contains(message, "'dy_mm' is missing")) << message;
  { hdf5::File file = hdf5::File::Create(dir / "nodata.h5"); }
  message = ErrorMessageOf([&] { (void)ReadErrorMapHdf5(dir / "nodata.h5"); });
  EXPECT_TRUE(Contains(message, "nodata.h5'") && Contains(message, "'error_um' is missing")) << message;
}

// ------------------------------------------------------------------------------------------------
// Scattered points.

struct P2 {
  double x, y;
};
double Cross(const P2& o, const P2& a, const P2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// Convex hull (Andrew's monotone chain), counter-clockwise: an independent check of the hull.
std::vector<P2> Hull(std::vector<P2> p) {
  std::sort(p.begin(), p.end(),
            [](const P2& a, const P2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  std::vector<P2> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && Cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && Cross(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

// Signed distance to the hull boundary: > 0 inside.
double InsideBy(const std::vector<P2>& hull, double x, double y) {
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < hull.size(); ++k) {
    const P2 &a = hull[k], &b = hull[(k + 1) % hull.size()];
    d = std::min(d, Cross(a, b, {x, y}) / std::hypot(b.x - a.x, b.y - a.y));
  }
  return d;
}

std::vector<ScatteredPoint> RandomPoints(int count, const std::function<double(double, double)>& f,
                                         unsigned seed) {
  std::mt19937 rng(seed);  // fixed seed: a failure must reproduce
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  std::vector<ScatteredPoint> points;
  for (int k = 0; k < count; ++k) {
    const double x = u(rng), y = 0.6 * u(rng) + 3.0;
    points.push_back({x, y, f(x, y)});
  }
  return points;
}

TEST(InterpolateScattered, ReproducesAPlaneExactlyAndLeavesNodesOutsideTheHullWithoutData) {
  auto plane = [](double x, double y) { return 0.3 * x - 0.7 * y + 2.0; };
  const std::vector<ScatteredPoint> points = RandomPoints(300, plane, 20240611);
  const ErrorMap map = InterpolateScattered(points, 0.5, "cmm.csv");
  EXPECT_EQ(map.grid.dx_mm, 0.5);
  std::vector<P2> xy;
  for (const ScatteredPoint& p : points) xy.push_back({p.x_mm, p.y_mm});
  const std::vector<P2> hull = Hull(xy);
  int inside = 0;
  for (int j = 0; j < map.grid.ny; ++j) {
    for (int i = 0; i < map.grid.nx; ++i) {
      const double d = InsideBy(hull, map.grid.X(i), map.grid.Y(j));
      if (d > 1e-9) {
        ++inside;
        ASSERT_TRUE(std::isfinite(map.At(i, j)))
            << "node (" << map.grid.X(i) << ", " << map.grid.Y(j) << ") inside the hull by " << d;
        EXPECT_NEAR(map.At(i, j), plane(map.grid.X(i), map.grid.Y(j)), 1e-12);
      } else if (d < -1e-9) {
        EXPECT_TRUE(std::isnan(map.At(i, j)))
            << "node (" << map.grid.X(i) << ", " << map.grid.Y(j) << ") outside the hull";
      }
    }
  }
  EXPECT_GT(inside, 1000);
  // Nodes sit at whole multiples of the spacing.
  EXPECT_NEAR(std::remainder(map.grid.x0_mm, 0.5), 0.0, 1e-12);
  EXPECT_NEAR(std::remainder(map.grid.y0_mm, 0.5), 0.0, 1e-12);
}

// A square lattice (every four neighbours on one circle: the Delaunay triangulation is not unique)
// far from the origin: every point stays a vertex, and a plane comes back on every node.
TEST(InterpolateScattered, ReproducesAPlaneOnACocircularLatticeFarFromTheOrigin) {
  auto plane = [](double x, double y) { return 0.3 * (x - 1e4) - 0.7 * (y + 5e3) + 2.0; };
  std::vector<ScatteredPoint> points;
  for (int j = 0; j <= 20; ++j)
    for (int i = 0; i <= 30; ++i) {
      const double x = 1e4 + 1.5 * i, y = -5e3 + 1.5 * j;
      points.push_back({x, y, plane(x, y)});
    }
  const ErrorMap map = InterpolateScattered(points, 0.5, "lattice.csv");
  EXPECT_EQ(map.grid.nx, 91);
  EXPECT_EQ(map.grid.ny, 61);
  for (int j = 0; j < map.grid.ny; ++j)
    for (int i = 0; i < map.grid.nx; ++i) {
      ASSERT_TRUE(std::isfinite(map.At(i, j))) << i << ", " << j;
      EXPECT_NEAR(map.At(i, j), plane(map.grid.X(i), map.grid.Y(j)), 1e-9);
    }
}

TEST(InterpolateScattered, StaysWithinTheLinearInterpolationBoundOfAQuadratic) {
  // Points on a jittered square lattice of pitch h (each moved by at most 0.3 h per axis). For
  // f = x^2 + y^2 the linear interpolant over a triangle exceeds f by R^2 - |p - c|^2, R and c the
  // circumcircle's radius and centre, so 0 <= error <= R^2. A Delaunay circumcircle holds no
  // point, and the lattice leaves no empty disc wider than r = h / sqrt(2) + 0.3 sqrt(2) h with
  // its centre among the points. The circumcircle through a node p holds a disc of radius
  // min(R, r) centred within r of p, so for nodes more than r + h inside the lattice R <= r.
  // (Near the hull, Delaunay triangles may be long slivers: no such bound there.)
  const double h = 2.0;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3 * h, 0.3 * h);
  std::vector<ScatteredPoint> points;
  for (int j = -10; j <= 10; ++j) {
    for (int i = -10; i <= 10; ++i) {
      const double x = i * h + jitter(rng), y = j * h + jitter(rng);
      points.push_back({x, y, x * x + y * y});
    }
  }
  const ErrorMap map = InterpolateScattered(points, 0.37, "quad.csv");
  const double r_max = h / std::sqrt(2.0) + 0.3 * std::sqrt(2.0) * h;
  int checked = 0;
  for (int j = 0; j < map.grid.ny; ++j) {
    for (int i = 0; i < map.grid.nx; ++i) {
      if (std::max(std::abs(map.grid.X(i)), std::abs(map.grid.Y(j))) > 10 * h - r_max - h) continue;
      ASSERT_TRUE(std::isfinite(map.At(i, j)));
      const double error = map.At(i, j) - (map.grid.X(i) * map.grid.X(i) + map.grid.Y(j) * map.grid.Y(j));
      EXPECT_GE(error, -1e-9);
      EXPECT_LE(error, r_max * r_max);
      ++checked;
    }
  }
  EXPECT_GT(checked, 5000);
}

TEST(InterpolateScattered, DefaultsTheSpacingToTheMedianNearestNeighbourDistance) {
  const std::vector<ScatteredPoint> points = RandomPoints(
      101, [](double, double) { return 0.0; }, 99);
  std::vector<double> nearest;
  for (std::size_t a = 0; a < points.size(); ++a) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t b = 0; b < points.size(); ++b) {
      if (a != b)
        best = std::min(best, std::hypot(points[a].x_mm - points[b].x_mm, points[a].y_mm - points[b].y_mm));
    }
    nearest.push_back(best);
  }
  std::sort(nearest.begin(), nearest.end());
  EXPECT_DOUBLE_EQ(MedianNearestNeighbourMm(points, "p.csv"), nearest[50]);
  EXPECT_DOUBLE_EQ(InterpolateScattered(points, 0.0, "p.csv").grid.dx_mm, nearest[50]);
}

TEST(ReadScatteredCsv, RefusesTooFewCollinearOrCoincidentPointsNamingTheFile) {
  arcwheel::testing::TempDir dir;
  auto error = [&](const std::string& text) {
    std::ofstream(dir / "pts.csv") << text;
    return ErrorMessageOf([&] {
      (void)InterpolateScattered(ReadScatteredCsv(dir / "pts.csv"), 1.0, (dir / "pts.csv").string());
    });
  };
  std::string m = error("x_mm,y_mm,error_um\n0,0,1\n1,0,2\n");
  EXPECT_TRUE(Contains(m, "pts.csv'") && Contains(m, "2 scattered points")) << m;
  m = error("x_mm,y_mm,error_um\n0,0,1\n1,1,2\n2,2,3\n3,3,1\n");
  EXPECT_TRUE(Contains(m, "pts.csv'") && Contains(m, "one line")) << m;
  m = error("x_mm,y_mm,error_um\n0,0,1\n1,0,2\n0,1,3\n# repeat\n1,0,5\n");
  EXPECT_TRUE(Contains(m, "pts.csv'") && Contains(m, "line 3") && Contains(m, "line 6") &&
              Contains(m, "one place"))
      << m;
  // Two points 1e-11 of the map's size apart, inside the hull (qhull keeps both).
  m = error("x_mm,y_mm,error_um\n0,0,1\n10,0,2\n0,10,3\n10,10,4\n5,5,1\n5,5.0000000001,2\n");
  EXPECT_TRUE(Contains(m, "pts.csv'") && Contains(m, "line 6") && Contains(m, "line 7") &&
              Contains(m, "one place"))
      << m;
  m = error("x_mm,y_mm,error_um\n0,0,1\n1,0,nan\n0,1,3\n");
  EXPECT_TRUE(Contains(m, "pts.csv' line 3")) << m;
}

// ------------------------------------------------------------------------------------------------
// The job's error_map section.

std::string ErrorMapJob(const std::string& error_map) {
  return R"({"surface": {"vertex_radius_mm": 400.0, "form": "convex"},
             "aperture": {"diameter_mm": 20.0},
             "removal_function": {"peak_rate_um_per_s": 1.5, "fwhm_mm": 5.0},
             "machine": {"max_speed_mm_s": 150.0},
             "error_map": )" +
         error_map + "}";
}

PolishJob ReadJob(const arcwheel::testing::TempDir& dir, const std::string& error_map) {
  std::ofstream(dir / "job.json") << ErrorMapJob(error_map);
  return ReadPolishJob(dir / "job.json");
}

TEST(PolishJobErrorMap, ReadsEachFormatByItsExtensionAndAppliesThePlacementKeys) {
  arcwheel::testing::TempDir dir;
  const std::vector<unsigned char> dat = TestMetroProImage();
  WriteText(dir / "map.dat", std::string(dat.begin(), dat.end()));
  const PixelMap pixels = ParseMetroProDat(dat, "map.dat");
  PolishJob job =
      ReadJob(dir, R"({"file": "map.dat", "rotation_deg": 90, "scale": -1, "centre_mm": [1, 2]})");
  const ErrorMap expected = PlaceInPartFrame(
      pixels, {.centre_x_mm = 1, .centre_y_mm = 2, .rotation_deg = 90, .scale = -1}, "map.dat");
  EXPECT_EQ(job.error_map.grid.nx, 5);
  EXPECT_EQ(job.error_map.grid.ny, 7);
  EXPECT_EQ(job.error_map.grid.x0_mm, expected.grid.x0_mm);
  for (std::size_t k = 0; k < expected.error_um.size(); ++k) {
    EXPECT_TRUE(job.error_map.error_um[k] == expected.error_um[k] ||
                (std::isnan(job.error_map.error_um[k]) && std::isnan(expected.error_um[k])));
  }
  const nlohmann::json resolved = nlohmann::json::parse(job.resolved_json);
  EXPECT_EQ(resolved["error_map"]["centre_px"], nlohmann::json::array({3.0, 2.0}));
  EXPECT_EQ(resolved["error_map"]["format"], "dat");

  std::ofstream(dir / "pts.csv") << "x_mm,y_mm,error_um\n-10,-10,1\n10,-10,1\n0,10,1\n";
  job = ReadJob(dir, R"({"file": "pts.csv", "layout": "scattered", "grid_spacing_mm": 0.5})");
  EXPECT_EQ(job.error_map.grid.dx_mm, 0.5);
  EXPECT_NEAR(job.error_map.At(20, 20), 1.0, 1e-12);  // (0, 0) lies inside the triangle

  ErrorMap grid{.grid = {.x0_mm = -10, .y0_mm = -10, .dx_mm = 1, .dy_mm = 1, .nx = 21, .ny = 21},
                .error_um = std::vector<double>(441, 0.5)};
  WriteErrorMapHdf5(grid, dir / "grid.h5");
  job = ReadJob(dir, R"({"file": "grid.h5", "scale": 2})");
  EXPECT_EQ(job.error_map.At(3, 4), 1.0);
}

TEST(PolishJobErrorMap, RefusesUnknownAndMisappliedKeysByDottedName) {
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "map.csv") << "x_mm,y_mm,error_um\n0,0,1\n1,0,1\n";
  auto message = [&](const std::string& error_map) {
    return ErrorMessageOf([&] { (void)ReadJob(dir, error_map); });
  };
  EXPECT_TRUE(
      Contains(message(R"({"file": "map.csv", "pixel_size": 1})"), "unknown key 'error_map.pixel_size'"));
  EXPECT_TRUE(Contains(message(R"({"file": "map.csv", "rotation_deg": 90})"),
                       "'error_map.rotation_deg' applies only"));
  EXPECT_TRUE(Contains(message(R"({"file": "map.csv", "grid_spacing_mm": 1})"),
                       "'error_map.grid_spacing_mm' applies only"));
  EXPECT_TRUE(
      Contains(message(R"({"file": "map.csv", "format": "zyg"})"),
               "key 'error_map.format' expected one of \"csv\", \"dat\", \"datx\", \"h5\", got \"zyg\""));
  EXPECT_TRUE(Contains(message(R"({"file": "map.txt"})"), "'error_map.format' is required"));
  EXPECT_TRUE(Contains(message(R"({"file": "map.csv", "scale": 0})"), "'error_map.scale' must be non-zero"));
}

// The fuzzer seeds of fuzz/seeds/ (map_small.dat, map_small.datx, map_small_grid.h5,
// map_scattered.csv): written to a temporary folder and read back by the readers they seed; with
// ARCWHEEL_WRITE_SEEDS=fuzz/seeds they are also copied there.
TEST(ErrorMapSeeds, SmallSamplesOfEachFormatReadBack) {
  arcwheel::testing::TempDir dir;
  const std::vector<unsigned char> dat = TestMetroProImage();
  WriteText(dir / "map_small.dat", std::string(dat.begin(), dat.end()));
  WriteDatx(dir / "map_small.datx", DatxSpec{}, 6, 4, DatxHeightNm);
  ErrorMap grid{.grid = {.x0_mm = -2, .y0_mm = -1, .dx_mm = 1, .dy_mm = 1, .nx = 5, .ny = 3}, .error_um = {}};
  for (int k = 0; k < 15; ++k) grid.error_um.push_back(k == 4 ? kNaN : 0.05 * k);
  WriteErrorMapHdf5(grid, dir / "map_small_grid.h5");
  {
    std::ofstream csv(dir / "map_scattered.csv");
    csv << "x_mm,y_mm,error_um\n";
    for (const ScatteredPoint& p : RandomPoints(
             12, [](double x, double y) { return 0.01 * x * y; }, 5)) {
      csv << p.x_mm << "," << p.y_mm << "," << p.error_um << "\n";
    }
  }
  EXPECT_EQ(ReadMetroProDat(dir / "map_small.dat").width, 7);
  EXPECT_EQ(ReadZygoDatx(dir / "map_small.datx").width, 6);
  EXPECT_EQ(ReadErrorMapHdf5(dir / "map_small_grid.h5").grid.nx, 5);
  EXPECT_GT(
      InterpolateScattered(ReadScatteredCsv(dir / "map_scattered.csv"), 0.0, "map_scattered.csv").grid.nx, 1);
  if (const char* folder = std::getenv("ARCWHEEL_WRITE_SEEDS")) {
    for (const char* name : {"map_small.dat", "map_small.datx", "map_small_grid.h5", "map_scattered.csv"}) {
      std::filesystem::copy_file(dir / name, std::filesystem::path(folder) / name,
                                 std::filesystem::copy_options::overwrite_existing);
    }
  }
}

}  // namespace
}  // namespace arcwheel::polishing
