// Tests of the LAS reader (read_points and scan_points on ASPRS LAS files): every point record
// format 0-10 with exact coordinates, extra bytes, wrong VLR counts, padding, LAS 1.4 counts,
// georeferenced offsets, LAZ refused, every lying header refused with a message naming the file,
// and the real LAS files of $G2S_DATA_DIR/las with the counts from its README.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "io/readers.hpp"
#include "support/cli.hpp"
#include "support/las_writer.hpp"
#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;
using g2s::test_support::las_bytes;
using g2s::test_support::LasSpec;
using Points = std::vector<std::array<std::int32_t, 3>>;

const Points kPoints = {{0, 0, 0}, {100, -250, 7}, {-2147483647, 2147483647, 12345}, {1, 2, 3}};

class LasRead : public ::testing::Test {
 protected:
  fs::path write(const std::string& name, const std::string& bytes) {
    const fs::path path = folder_.path() / name;
    std::ofstream(path, std::ios::binary)
        .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path;
  }
  // The points as the specification defines them: integer * scale + offset, in double.
  static std::vector<double> expected(const LasSpec& spec, const Points& points) {
    std::vector<double> xyz;
    for (const auto& p : points) {
      for (int a = 0; a < 3; ++a)
        xyz.push_back(static_cast<double>(p[a]) * spec.scale[a] + spec.offset[a]);
    }
    return xyz;
  }
  // Reads the file both ways (collected and streamed) and checks the exact coordinates.
  void expect_points(const fs::path& path, const LasSpec& spec, const Points& points) {
    g2s::ReadReport report;
    const g2s::PointCloud cloud = g2s::read_points(path, &report);
    EXPECT_EQ(cloud.xyz, expected(spec, points));
    EXPECT_EQ(report.points, points.size());
    EXPECT_EQ(report.declared, points.size());
    EXPECT_EQ(report.format,
              "las-1." + std::to_string(spec.minor) + "-format" + std::to_string(spec.format));
    std::vector<double> streamed;
    g2s::ReadReport scan_report;
    g2s::io::scan_points(
        path,
        [&](std::span<const double> run) {
          streamed.insert(streamed.end(), run.begin(), run.end());
        },
        scan_report);
    EXPECT_EQ(streamed, cloud.xyz);
    EXPECT_EQ(scan_report.points, report.points);
  }
  void expect_refused(const LasSpec& spec, const Points& points,
                      std::initializer_list<std::string_view> parts) {
    SCOPED_TRACE(*parts.begin());
    const fs::path path = write("bad.las", las_bytes(spec, points));
    for (const bool stream : {false, true}) {
      try {
        g2s::ReadReport report;
        if (stream) {
          g2s::io::scan_points(
              path, [](std::span<const double>) {}, report);
        } else {
          g2s::read_points(path, &report);
        }
        ADD_FAILURE() << "no exception thrown";
      } catch (const g2s::Error& e) {
        EXPECT_EQ(e.code(), g2s::Exit::bad_input) << e.what();
        const std::string_view what = e.what();
        EXPECT_NE(what.find(path.string()), std::string_view::npos) << what;
        for (std::string_view part : parts) {
          EXPECT_NE(what.find(part), std::string_view::npos)
              << "message: " << what << "\nshould contain: " << part;
        }
      }
    }
  }
  g2s::test_support::TempFolder folder_{"g2s-las-read"};
};

TEST_F(LasRead, EveryRecordFormatOfEveryVersion) {
  for (unsigned minor = 0; minor <= 4; ++minor) {
    // Formats 2-3 came with LAS 1.2, 4-5 with 1.3, 6-10 with 1.4; a reader need not care.
    const unsigned formats = minor < 2 ? 2 : minor == 2 ? 4 : minor == 3 ? 6 : 11;
    for (unsigned format = 0; format < formats; ++format) {
      SCOPED_TRACE(testing::Message() << "LAS 1." << minor << " format " << format);
      LasSpec spec;
      spec.minor = minor;
      spec.format = format;
      spec.scale[0] = 0.001;
      spec.scale[2] = 0.25;
      spec.offset[0] = -5.5;
      spec.offset[1] = 1000.0;
      expect_points(write("f.las", las_bytes(spec, kPoints)), spec, kPoints);
    }
  }
}

TEST_F(LasRead, ExtraBytesAreSteppedOverByTheRecordLength) {
  for (unsigned format : {0U, 3U, 6U, 10U}) {
    LasSpec spec;
    spec.minor = 4;
    spec.format = format;
    spec.extra_bytes = 27;
    expect_points(write("extra.las", las_bytes(spec, kPoints)), spec, kPoints);
  }
}

TEST_F(LasRead, PointsAreFoundByTheOffsetNotByAddingUpVlrs) {
  for (const std::int64_t claimed : {0, 1, 7, 100000}) {
    SCOPED_TRACE(claimed);
    LasSpec spec;
    spec.vlr_payloads = {10, 300};
    spec.vlr_count_field = claimed;
    spec.padding = 13;  // some writers leave a gap (the old "start of data" bytes, alignment)
    expect_points(write("vlr.las", las_bytes(spec, kPoints)), spec, kPoints);
  }
}

TEST_F(LasRead, Las14CountsTheSixtyFourBitCount) {
  LasSpec spec;
  spec.minor = 4;
  spec.format = 6;
  spec.legacy_count = 0;  // as the specification asks for formats 6 and up
  expect_points(write("zero.las", las_bytes(spec, kPoints)), spec, kPoints);
  spec.legacy_count = 1;  // a stale legacy count
  expect_points(write("stale.las", las_bytes(spec, kPoints)), spec, kPoints);
  spec.format = 1;  // a 1.4 file written 1.2-style: only the legacy count
  spec.legacy_count = -1;
  spec.count_64 = 0;
  expect_points(write("legacy.las", las_bytes(spec, kPoints)), spec, kPoints);
}

TEST_F(LasRead, GeoreferencedCoordinatesAreExactInDouble) {
  LasSpec spec;
  spec.format = 1;
  spec.scale[0] = spec.scale[1] = spec.scale[2] = 0.001;
  spec.offset[0] = 636000.0;
  spec.offset[1] = 4848900.0;
  spec.offset[2] = 400.0;
  const Points points = {{123456, 654321, -100}, {-1, 1, 0}};
  const fs::path path = write("utm.las", las_bytes(spec, points));
  expect_points(path, spec, points);
  // A float would round 4849554.321 to 4849554.5: the reader must not.
  EXPECT_EQ(g2s::read_points(path).xyz[1], 654321 * 0.001 + 4848900.0);
}

TEST_F(LasRead, NoPointsIsAnEmptyCloud) {
  LasSpec spec;
  spec.minor = 4;
  spec.format = 7;
  g2s::ReadReport report;
  EXPECT_EQ(g2s::read_points(write("empty.las", las_bytes(spec, {})), &report).size(), 0U);
  EXPECT_EQ(report.points, 0U);
}

TEST_F(LasRead, ShortBodyIsRefused) {
  LasSpec spec;
  spec.format = 3;
  spec.drop_tail_bytes = 5;
  expect_refused(spec, kPoints, {"file ends inside point 4 of 4", "truncated"});
  spec.drop_tail_bytes = 34 * 4;
  expect_refused(spec, kPoints, {"point 1 of 4"});
}

TEST_F(LasRead, LyingHeadersAreRefused) {
  LasSpec spec;
  spec.format = 3;
  spec.record_length = 33;
  expect_refused(spec, kPoints, {"record length 33", "format 3", "34 bytes"});
  spec = {};
  spec.point_offset = 1 << 20;
  expect_refused(spec, kPoints, {"offset to point data 1048576", "past the end"});
  spec = {};
  spec.point_offset = 100;
  expect_refused(spec, kPoints, {"offset to point data 100", "header"});
  spec = {};
  spec.minor = 4;
  spec.count_64 = std::int64_t{1} << 62;  // count * record length overflows 64 bits
  expect_refused(spec, kPoints, {"of 4611686018427387904", "truncated"});
  spec = {};
  spec.legacy_count = 0xFFFFFFFF;
  expect_refused(spec, kPoints, {"of 4294967295"});
  spec = {};
  spec.format = 11;
  spec.record_length = 100;
  expect_refused(spec, kPoints, {"record format 11", "0 to 10"});
  spec = {};
  spec.minor = 4;
  spec.header_size = 227;
  expect_refused(spec, kPoints, {"header size 227", "375"});
  spec = {};
  spec.minor = 9;
  expect_refused(spec, kPoints, {"LAS version 1.9"});
  spec = {};
  spec.scale[1] = 0.0;
  expect_refused(spec, kPoints, {"y scale factor 0"});
}

TEST_F(LasRead, CutHeaderIsRefused) {
  const std::string bytes = las_bytes({}, kPoints);
  const fs::path path = write("cut.las", bytes.substr(0, 200));
  EXPECT_THROW(g2s::read_points(path), g2s::Error);
  try {
    g2s::read_points(path);
  } catch (const g2s::Error& e) {
    EXPECT_EQ(e.code(), g2s::Exit::bad_input);
    EXPECT_NE(std::string_view(e.what()).find("inside the LAS header"), std::string_view::npos)
        << e.what();
  }
}

TEST_F(LasRead, LazIsRefusedWithHowToDecompress) {
  LasSpec spec;
  spec.format = 3;
  spec.format_flags = 0x80;  // LASzip's compression bit
  expect_refused(spec, kPoints, {"LAZ", "laszip -i in.laz -o out.las", "pdal translate"});
  spec.format_flags = 0x40;  // older LASzip versions
  expect_refused(spec, kPoints, {"LAZ"});
  spec.format_flags = 0;  // the bit lost, the LASzip VLR still there
  spec.vlr_payloads = {34};
  spec.vlr_user = "laszip encoded";
  spec.vlr_record_id = 22204;
  expect_refused(spec, kPoints, {"LAZ"});
}

// The LAS files of PDAL's test suite (written by PDAL, Global Mapper, TerraScan), with the
// counts their README lists; autzen_trim.las holds the points of open-autzen-lidar.ply.
using g2s::test_support::data_dir;

TEST(LasRealFiles, CountsAndBoundsMatchTheReadme) {
  struct Case {
    const char* name;
    std::uint64_t points;
    const char* format;
  };
  const Case cases[] = {{"autzen_trim.las", 110000, "las-1.2-format3"},
                        {"test1_4.las", 1000, "las-1.4-format6"},
                        {"extrabytes.las", 1065, "las-1.4-format3"},
                        {"4_6_crop.las", 23875, "las-1.2-format3"},
                        {"simple.las", 1065, "las-1.2-format3"}};
  for (const Case& c : cases) G2S_SKIP_WITHOUT_DATA(data_dir() / "las" / c.name);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path path = data_dir() / "las" / c.name;
    g2s::ReadReport report;
    const g2s::PointCloud cloud = g2s::read_points(path, &report);
    EXPECT_EQ(report.points, c.points);
    EXPECT_EQ(report.format, c.format);
    EXPECT_EQ(report.non_finite, 0U);
  }
}

// The same 110,000 points: the PLY stores them shifted by (636000, 848900, 400) and rounded to
// float, so each LAS point must be within float rounding of the PLY's.
TEST(LasRealFiles, AutzenLasHoldsThePointsOfTheAutzenPly) {
  const fs::path las = data_dir() / "las" / "autzen_trim.las";
  const fs::path ply = data_dir() / "open-autzen-lidar.ply";
  G2S_SKIP_WITHOUT_DATA(las);
  G2S_SKIP_WITHOUT_DATA(ply);
  const g2s::PointCloud a = g2s::read_points(las);
  const g2s::PointCloud b = g2s::read_points(ply);
  ASSERT_EQ(a.size(), b.size());
  const double shift[3] = {636000.0, 848900.0, 400.0};
  double worst = 0.0;
  for (std::size_t i = 0; i < a.xyz.size(); ++i)
    worst = std::max(worst, std::abs(a.xyz[i] - (b.xyz[i] + shift[i % 3])));
  EXPECT_LT(worst, 1e-3);  // float keeps ~6e-5 ft at 1,000 ft; a wrong stride or scale is far off
}

}  // namespace
