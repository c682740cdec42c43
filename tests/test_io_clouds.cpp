#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/lzf.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::error_of;
using scanmatch::testing::expect_same_cloud;
using scanmatch::testing::TempDir;
using scanmatch::testing::write_text;
using Encoding = CloudWriteOptions::Encoding;

namespace {
PointCloud sample_cloud(std::size_t n, bool fields = true) {
  PointCloud c;
  for (std::size_t i = 0; i < n; ++i) {
    const float f = static_cast<float>(i);
    c.points.emplace_back(0.1f * f, -3.25f + 0.01f * f, std::sin(f) * 7.123456f);
    if (fields) {
      c.intensity.push_back(0.5f * f);
      c.ring.push_back(static_cast<std::uint16_t>(i % 64));
      c.time.push_back(1e-5f * f);
    }
  }
  return c;
}

std::string gzip(const std::string& data) {
  z_stream s{};
  deflateInit2(&s, 6, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY);
  std::string out(deflateBound(&s, data.size()) + 32, '\0');
  s.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  s.avail_in = static_cast<uInt>(data.size());
  s.next_out = reinterpret_cast<Bytef*>(out.data());
  s.avail_out = static_cast<uInt>(out.size());
  deflate(&s, Z_FINISH);
  out.resize(s.total_out);
  deflateEnd(&s);
  return out;
}
}  // namespace

TEST(CloudIo, RoundTripEveryFormatAndEncoding) {
  TempDir dir;
  const PointCloud cloud = sample_cloud(1000);
  for (auto enc : {Encoding::kAscii, Encoding::kBinary, Encoding::kBinaryCompressed}) {
    write_cloud(dir.file("a.pcd"), cloud, {enc});
    expect_same_cloud(read_cloud(dir.file("a.pcd")), cloud);
  }
  for (auto enc : {Encoding::kAscii, Encoding::kBinary}) {
    write_cloud(dir.file("a.ply"), cloud, {enc});
    expect_same_cloud(read_cloud(dir.file("a.ply")), cloud);
  }
  for (const char* name : {"a.csv", "a.xyz", "a.txt"}) {
    write_cloud(dir.file(name), cloud);
    expect_same_cloud(read_cloud(dir.file(name)), cloud);
  }
  // KITTI .bin keeps x y z intensity only.
  write_cloud(dir.file("a.bin"), cloud);
  const PointCloud bin = read_cloud(dir.file("a.bin"));
  EXPECT_EQ(bin.points, cloud.points);
  EXPECT_EQ(bin.intensity, cloud.intensity);
  EXPECT_FALSE(bin.has_ring());
}

TEST(CloudIo, RoundTripWithoutOptionalFieldsAndEmptyCloud) {
  TempDir dir;
  const PointCloud xyz = sample_cloud(50, false);
  for (auto enc : {Encoding::kAscii, Encoding::kBinary, Encoding::kBinaryCompressed}) {
    write_cloud(dir.file("b.pcd"), xyz, {enc});
    const PointCloud back = read_cloud(dir.file("b.pcd"));
    expect_same_cloud(back, xyz);
    EXPECT_FALSE(back.has_intensity());
  }
  write_cloud(dir.file("empty.pcd"), PointCloud{});
  EXPECT_TRUE(read_cloud(dir.file("empty.pcd")).empty());
}

TEST(CloudIo, GzipInputIsTransparent) {
  TempDir dir;
  const PointCloud cloud = sample_cloud(200);
  write_cloud(dir.file("c.pcd"), cloud, {Encoding::kBinary});
  std::ifstream in(dir.file("c.pcd"), std::ios::binary);
  const std::string raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  write_text(dir.file("c.pcd.gz"), gzip(raw));
  CloudFileInfo info;
  expect_same_cloud(read_cloud(dir.file("c.pcd.gz"), {}, &info), cloud);
  EXPECT_TRUE(info.compressed_gzip);
  // A truncated gzip stream is an error, not a short cloud.
  const std::string gz = gzip(raw);
  write_text(dir.file("d.pcd.gz"), gz.substr(0, gz.size() / 2));
  EXPECT_NE(error_of([&] { read_cloud(dir.file("d.pcd.gz")); }).find("d.pcd.gz"),
            std::string::npos);
}

TEST(Pcd, HandWrittenAsciiWithPaddingAndCountedFields) {
  const std::string text =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS normal_x x _ y z intensity\nSIZE 4 4 1 4 4 4\n"
      "TYPE F F U F F F\nCOUNT 3 1 4 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
      "POINTS 2\nDATA ascii\n0 0 1 1.5 0 0 0 0 2.5 -3.5 7\n1 1 1 4 9 9 9 9 5 6 8\n";
  CloudFileInfo info;
  const PointCloud c = parse_cloud(text, CloudFormat::kPcd, "hand.pcd", {}, &info);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[0], Point(1.5f, 2.5f, -3.5f));
  EXPECT_EQ(c.points[1], Point(4.0f, 5.0f, 6.0f));
  EXPECT_EQ(c.intensity, (std::vector<float>{7.0f, 8.0f}));
  EXPECT_EQ(info.fields.size(), 6u);
  EXPECT_EQ(info.encoding, "ascii");
}

TEST(Pcd, HandBuiltBinaryWithDoubleAndByteFields) {
  std::string bytes =
      "VERSION .7\nFIELDS ring x y z t\nSIZE 1 8 8 8 8\nTYPE U F F F F\nCOUNT 1 1 1 1 1\n"
      "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary\n";
  for (int i = 0; i < 2; ++i) {
    const std::uint8_t ring = static_cast<std::uint8_t>(10 + i);
    const double v[4] = {1.0 + i, 2.0, 3.0, 0.05 * i};
    bytes.append(reinterpret_cast<const char*>(&ring), 1);
    bytes.append(reinterpret_cast<const char*>(v), sizeof v);
  }
  const PointCloud c = parse_cloud(bytes, CloudFormat::kPcd, "hand.pcd");
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[1], Point(2, 2, 3));
  EXPECT_EQ(c.ring, (std::vector<std::uint16_t>{10, 11}));
  EXPECT_FLOAT_EQ(c.time[1], 0.05f);
}

TEST(Pcd, OrganisedCloudDropsOrKeepsNaN) {
  const std::string text =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA ascii\n"
      "1 2 3\nnan nan nan\n4 5 6\n7 inf 9\n";
  CloudFileInfo info;
  EXPECT_EQ(parse_cloud(text, CloudFormat::kPcd, "o.pcd", {}, &info).size(), 2u);
  EXPECT_EQ(info.non_finite, 2u);
  EXPECT_EQ(info.height, 2u);
  CloudReadOptions keep;
  keep.keep_non_finite = true;
  EXPECT_EQ(parse_cloud(text, CloudFormat::kPcd, "o.pcd", keep).size(), 4u);
}

TEST(Pcd, BadInputGivesClearErrors) {
  const std::string head = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\nPOINTS 3\n";
  const auto err = [](const std::string& bytes) {
    return error_of([&] { parse_cloud(bytes, CloudFormat::kPcd, "bad.pcd"); });
  };
  EXPECT_NE(err("").find("empty"), std::string::npos);
  EXPECT_NE(err(head + "DATA ascii\n1 2 3\n4 5 6\n").find("truncated"), std::string::npos);
  EXPECT_NE(err(head + "DATA ascii\n1 2 3\n4 5 6\n7 8 9\n1 1 1\n").find("more data rows"),
            std::string::npos);
  EXPECT_NE(err(head + "DATA ascii\n1 2 3\n4 x 6\n7 8 9\n").find("line 9"), std::string::npos);
  EXPECT_NE(err(head + "DATA ascii\n1 2 3\n1 2\n4 5 6\n").find("expected 3 values"),
            std::string::npos);
  EXPECT_NE(err(head + "DATA binary\n" + std::string(20, '\0')).find("truncated"),
            std::string::npos);
  EXPECT_NE(err(head + "DATA lzma\n").find("unknown DATA"), std::string::npos);
  EXPECT_NE(err("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\nPOINTS 4\nDATA ascii\n")
                .find("disagrees"),
            std::string::npos);
  EXPECT_NE(
      err("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH -3\nHEIGHT 1\nDATA ascii\n").find("WIDTH"),
      std::string::npos);
  // A huge claimed count on a tiny file must be refused before any allocation.
  EXPECT_NE(
      err("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 99999999999\nHEIGHT 1\nDATA binary\nabc")
          .find("truncated"),
      std::string::npos);
  EXPECT_NE(err("FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n").find("SIZE"),
            std::string::npos);
  EXPECT_NE(err("FIELDS x y z\nSIZE 4 4 4\nTYPE F F Q\nWIDTH 1\nDATA ascii\n1 2 3\n").find("TYPE"),
            std::string::npos);
  EXPECT_NE(err("FIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 1\nDATA ascii\n1 2\n").find("no x, y and z"),
            std::string::npos);
  EXPECT_NE(err("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\n").find("no DATA"),
            std::string::npos);
  EXPECT_EQ(err(head + "DATA ascii\n1 2 3\n4 5 6\n7 8 9\n"), "");
}

TEST(Pcd, CorruptCompressedDataIsRejected) {
  const std::string head =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary_compressed\n";
  const auto with_sizes = [&](std::uint32_t compressed, std::uint32_t uncompressed,
                              const std::string& payload) {
    std::string b = head;
    b.append(reinterpret_cast<const char*>(&compressed), 4);
    b.append(reinterpret_cast<const char*>(&uncompressed), 4);
    return b + payload;
  };
  const auto err = [](const std::string& bytes) {
    return error_of([&] { parse_cloud(bytes, CloudFormat::kPcd, "bad.pcd"); });
  };
  // Back-reference before the start of the output.
  EXPECT_NE(err(with_sizes(2, 24, std::string("\x20\x05", 2))).find("before the start"),
            std::string::npos);
  // Uncompressed size disagreeing with the header.
  EXPECT_NE(err(with_sizes(2, 25, std::string("\x00\x01", 2))).find("disagrees"),
            std::string::npos);
  // Compressed size beyond the file.
  EXPECT_NE(err(with_sizes(1000, 24, "abc")).find("truncated"), std::string::npos);
  // Literal run past the end of the input.
  EXPECT_NE(err(with_sizes(2, 24, std::string("\x1f\x01", 2))).find("past the end"),
            std::string::npos);
}

TEST(Lzf, RoundTripsAndCompressesRepetitiveData) {
  std::string data;
  for (int i = 0; i < 5000; ++i) data += "scanmatch" + std::to_string(i % 13);
  const std::string packed = lzf_compress(data);
  EXPECT_LT(packed.size(), data.size() / 3);
  EXPECT_EQ(lzf_decompress(packed, data.size(), "t"), data);
  std::string random_bytes;
  std::uint32_t x = 1;
  for (int i = 0; i < 10000; ++i)
    random_bytes.push_back(static_cast<char>((x = x * 1664525u + 1013904223u) >> 24));
  EXPECT_EQ(lzf_decompress(lzf_compress(random_bytes), random_bytes.size(), "t"), random_bytes);
  EXPECT_EQ(lzf_decompress(lzf_compress(""), 0, "t"), "");
  EXPECT_THROW(lzf_decompress(packed, data.size() + 1, "t"), Error);
}

TEST(Ply, HandWrittenBigEndianAndMeshWithFaces) {
  std::string be =
      "ply\nformat binary_big_endian 1.0\ncomment hand made\nelement vertex 2\nproperty double x\n"
      "property float y\nproperty float z\nproperty uchar intensity\nend_header\n";
  const auto put_be = [&](const void* p, int n) {
    const char* c = static_cast<const char*>(p);
    for (int i = n - 1; i >= 0; --i) be.push_back(c[i]);
  };
  for (int i = 0; i < 2; ++i) {
    const double x = 1.25 + i;
    const float y = -2.0f, z = 3.5f;
    put_be(&x, 8);
    put_be(&y, 4);
    put_be(&z, 4);
    be.push_back(static_cast<char>(200));
  }
  const PointCloud c = parse_cloud(be, CloudFormat::kPly, "be.ply");
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[1], Point(2.25f, -2.0f, 3.5f));
  EXPECT_EQ(c.intensity[0], 200.0f);

  const std::string mesh =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(parse_cloud(mesh, CloudFormat::kPly, "mesh.ply").size(), 3u);

  // Binary mesh whose face element (with a list) comes before the vertices.
  std::string faces_first =
      "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uchar int "
      "vertex_indices\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  faces_first.push_back(3);
  const int idx[3] = {0, 0, 0};
  faces_first.append(reinterpret_cast<const char*>(idx), sizeof idx);
  const float v[3] = {7, 8, 9};
  faces_first.append(reinterpret_cast<const char*>(v), sizeof v);
  const PointCloud f = parse_cloud(faces_first, CloudFormat::kPly, "faces.ply");
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f.points[0], Point(7, 8, 9));
}

TEST(Ply, BadInputGivesClearErrors) {
  const auto err = [](const std::string& bytes) {
    return error_of([&] { parse_cloud(bytes, CloudFormat::kPly, "bad.ply"); });
  };
  const std::string head =
      "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  EXPECT_NE(err("").find("empty"), std::string::npos);
  EXPECT_NE(err("plx\n").find("magic"), std::string::npos);
  EXPECT_NE(err(head + std::string(30, '\0')).find("truncated"), std::string::npos);
  EXPECT_NE(
      err("ply\nformat binary_little_endian 1.0\nelement vertex 99999999999\nproperty float x\n"
          "property float y\nproperty float z\nend_header\nab")
          .find("truncated"),
      std::string::npos);
  EXPECT_NE(err("ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar int x\nend_header\n")
                .find("list property"),
            std::string::npos);
  EXPECT_NE(err("ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n")
                .find("unknown property type"),
            std::string::npos);
  EXPECT_NE(err("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n1 2\n")
                .find("line 8"),
            std::string::npos);
  EXPECT_NE(err("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n").find("end_header"),
            std::string::npos);
}

TEST(KittiBin, SizeMustBeMultipleOfSixteen) {
  TempDir dir;
  write_text(dir.file("bad.bin"), std::string(20, '\0'));
  const std::string message = error_of([&] { read_cloud(dir.file("bad.bin")); });
  EXPECT_NE(message.find("bad.bin"), std::string::npos);
  EXPECT_NE(message.find("20 bytes"), std::string::npos);
  write_text(dir.file("empty.bin"), "");
  EXPECT_THROW(read_cloud(dir.file("empty.bin")), Error);
}

TEST(TextCloud, HeaderlessColumnsCommentsAndErrors) {
  const PointCloud four =
      parse_cloud("# comment\n1 2 3 9\n4,5,6,10\n", CloudFormat::kText, "a.xyz");
  ASSERT_EQ(four.size(), 2u);
  EXPECT_EQ(four.intensity, (std::vector<float>{9, 10}));
  EXPECT_FALSE(parse_cloud("1 2 3\n", CloudFormat::kText, "a.xyz").has_intensity());
  const PointCloud named = parse_cloud("t,z,y,x\n0.5,3,2,1\n", CloudFormat::kText, "a.csv");
  EXPECT_EQ(named.points[0], Point(1, 2, 3));
  EXPECT_FLOAT_EQ(named.time[0], 0.5f);
  const auto err = [](const std::string& bytes) {
    return error_of([&] { parse_cloud(bytes, CloudFormat::kText, "bad.csv"); });
  };
  EXPECT_NE(err("1 2 3\n4 5\n").find("line 2"), std::string::npos);
  EXPECT_NE(err("1 2 3\n4 five 6\n").find("not a number"), std::string::npos);
  EXPECT_NE(err("").find("no points"), std::string::npos);
  EXPECT_NE(err("a,b,c\n1,2,3\n").find("no x, y and z"), std::string::npos);
}

TEST(CloudIo, UnknownExtensionAndMissingFile) {
  EXPECT_NE(error_of([] { read_cloud("/nonexistent/cloud.pcd"); }).find("/nonexistent/cloud.pcd"),
            std::string::npos);
  EXPECT_NE(error_of([] { read_cloud("cloud.las"); }).find("unknown point cloud format"),
            std::string::npos);
}

TEST(CloudIo, AtomicWriteLeavesNoTemporaryFiles) {
  TempDir dir;
  write_cloud(dir.file("x.pcd"), sample_cloud(10));
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 1u);
  EXPECT_THROW(write_cloud(dir.file("missing/x.pcd"), sample_cloud(10)), Error);
}

TEST(RealData, ReadsHdl32PlyAndCarCsv) {
  const std::string ply = scanmatch::testing::shared_data("data/3d/hdl32_pair/source.ply");
  const std::string csv = scanmatch::testing::shared_data("data/3d/car_pair/car_cloud400.csv");
  if (ply.empty() || csv.empty()) GTEST_SKIP() << "../shared/data/3d not present";
  CloudFileInfo info;
  const PointCloud cloud = read_cloud(ply, {}, &info);
  EXPECT_EQ(cloud.size(), 69792u);
  EXPECT_TRUE(cloud.has_intensity());
  EXPECT_EQ(info.encoding, "binary_little_endian");
  const PointCloud car = read_cloud(csv);
  EXPECT_GT(car.size(), 1000u);
  EXPECT_FALSE(car.has_intensity());
}

TEST(Parsers, CloudLinesOfOnlySeparatorsAreSkipped) {
  EXPECT_EQ(parse_cloud(",,;\n1 2 3\n", CloudFormat::kText, "sep.csv").size(), 1u);
  EXPECT_EQ(parse_cloud(",,\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n",
                        CloudFormat::kPcd, "sep.pcd")
                .size(),
            1u);
}
