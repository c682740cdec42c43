// Bag readers: small ROS 1 bags, MCAP files and ROS 2 .db3 files written by tests/bag_writer.hpp
// are read back and decoded exactly; broken inputs fail with scanmatch::Error.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>

#include "bag_writer.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/io/bag/bag.hpp"
#include "scanmatch/io/bag/ros_messages.hpp"
#include "test_helpers.hpp"

namespace scanmatch {
namespace {
using namespace scanmatch::test;
namespace fs = std::filesystem;

constexpr std::int64_t kT0 = 1700000000LL * 1000000000LL;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Case {
  std::vector<TestTopic> topics;
  std::vector<TestMessage> messages;                        // in file order
  std::map<std::string, std::vector<PointCloud>> clouds;    // expected, in time order
  std::map<std::string, std::vector<std::int64_t>> stamps;  // header stamps, in time order
  std::vector<LaserScan2D> scans;
};

std::string ros_type(bool cdr, const std::string& pkg, const std::string& name) {
  return cdr ? pkg + "/msg/" + name : pkg + "/" + name;
}

/// Ouster-like: float xyz, float intensity, u32 `t` in ns, u16 reflectivity and ring; 2 rows
/// with padding; one NaN point.
std::string ouster_cloud(bool cdr, std::int64_t stamp, int seed, PointCloud& expected) {
  const std::vector<TestField> fields = {{"x", 7, 0},    {"y", 7, 4},
                                         {"z", 7, 8},    {"intensity", 7, 16},
                                         {"t", 6, 20},   {"reflectivity", 4, 24},
                                         {"ring", 4, 26}};
  std::vector<std::vector<double>> values;
  for (int i = 0; i < 6; ++i) {
    const double x = i == 4 ? kNaN : 0.25 * i + seed, y = -1.5 * i, z = 0.125 * seed;
    const double t = 1000.0 * i + 17 + seed;
    values.push_back({x, y, z, 10.0 * i + 0.5, t, 99, static_cast<double>(i % 3)});
    if (i == 4) continue;
    expected.points.emplace_back(static_cast<float>(x), static_cast<float>(y),
                                 static_cast<float>(z));
    expected.intensity.push_back(static_cast<float>(10.0 * i + 0.5));
    expected.ring.push_back(static_cast<std::uint16_t>(i % 3));
    expected.time.push_back(static_cast<float>(t * 1e-9));
  }
  return point_cloud2(cdr, stamp, fields, 32, values, 2, 8);
}

/// Double xyz, u8 intensity, u16 "line", absolute double "timestamp" (made relative).
std::string double_cloud(bool cdr, std::int64_t stamp, PointCloud& expected) {
  const std::vector<TestField> fields = {{"x", 8, 0},     {"y", 8, 8},
                                         {"z", 8, 16},    {"intensity", 2, 24},
                                         {"line", 4, 26}, {"timestamp", 8, 28}};
  std::vector<std::vector<double>> values;
  const double start = static_cast<double>(stamp) * 1e-9;
  for (int i = 0; i < 4; ++i) {
    const double ts = start + 1e-4 * (3 - i);
    values.push_back({1.0 / 3 + i, 2.0, -0.1 * i, 200.0 + i, 15.0 - i, ts});
    expected.points.emplace_back(static_cast<float>(1.0 / 3 + i), 2.0f,
                                 static_cast<float>(-0.1 * i));
    expected.intensity.push_back(static_cast<float>(200 + i));
    expected.ring.push_back(static_cast<std::uint16_t>(15 - i));
  }
  for (int i = 0; i < 4; ++i)
    expected.time.push_back(static_cast<float>(values[i][5] - values[3][5]));
  return point_cloud2(cdr, stamp, fields, 36, values);
}

/// Big-endian int16 xyz with a float "time" in seconds and no other fields.
std::string big_endian_cloud(bool cdr, std::int64_t stamp, PointCloud& expected) {
  const std::vector<TestField> fields = {{"x", 3, 0}, {"y", 3, 2}, {"z", 3, 4}, {"time", 7, 8}};
  std::vector<std::vector<double>> values;
  for (int i = 0; i < 3; ++i) {
    values.push_back({-300.0 + i, 7.0 * i, 1000.0, 0.025 * i});
    expected.points.emplace_back(-300.0f + i, 7.0f * i, 1000.0f);
    expected.time.push_back(static_cast<float>(static_cast<double>(0.025f * i)));
  }
  return point_cloud2(cdr, stamp, fields, 12, values, 1, 0, true);
}

std::string livox_cloud(bool cdr, std::int64_t stamp, PointCloud& expected) {
  std::vector<TestLivoxPoint> points;
  for (int i = 0; i < 5; ++i) {
    const auto offset = static_cast<std::uint32_t>(100000 * i + 3);
    points.push_back({offset, 1.0f + i, -2.0f, 0.5f * i, static_cast<std::uint8_t>(10 * i), 0,
                      static_cast<std::uint8_t>(i % 4)});
    expected.points.emplace_back(1.0f + i, -2.0f, 0.5f * i);
    expected.intensity.push_back(static_cast<float>(10 * i));
    expected.ring.push_back(static_cast<std::uint16_t>(i % 4));
    expected.time.push_back(static_cast<float>(offset * 1e-9));
  }
  return livox_custom(cdr, stamp, points);
}

Case make_case(bool cdr) {
  Case c;
  c.topics = {
      {"/points", ros_type(cdr, "sensor_msgs", "PointCloud2")},
      {"/points_f64", ros_type(cdr, "sensor_msgs", "PointCloud2")},
      {"/points_be", ros_type(cdr, "sensor_msgs", "PointCloud2")},
      {"/livox", ros_type(cdr, cdr ? "livox_ros_driver2" : "livox_ros_driver", "CustomMsg")},
      {"/scan", ros_type(cdr, "sensor_msgs", "LaserScan")},
      {"/chatter", ros_type(cdr, "std_msgs", "String")}};
  // File order is not time order: /points frame 2 is written before frame 1.
  const std::int64_t times[] = {kT0 + 300000000, kT0 + 100000000, kT0 + 200000000};
  PointCloud p[3];
  for (int k : {0, 1, 2}) {
    c.messages.push_back({"/points", times[k], ouster_cloud(cdr, times[k] - 5000, k, p[k])});
    c.messages.push_back({"/chatter", times[k] + 1, std::string("\x02\0\0\0hi", 6)});
  }
  c.clouds["/points"] = {p[1], p[2], p[0]};
  c.stamps["/points"] = {times[1] - 5000, times[2] - 5000, times[0] - 5000};
  PointCloud d, b, l;
  c.messages.push_back({"/points_f64", kT0 + 50, double_cloud(cdr, kT0 + 40, d)});
  c.messages.push_back({"/points_be", kT0 + 60, big_endian_cloud(cdr, kT0 + 60, b)});
  c.messages.push_back({"/livox", kT0 + 70, livox_cloud(cdr, kT0 + 65, l)});
  c.clouds["/points_f64"] = {d};
  c.clouds["/points_be"] = {b};
  c.clouds["/livox"] = {l};
  c.stamps["/points_f64"] = {kT0 + 40};
  c.stamps["/points_be"] = {kT0 + 60};
  c.stamps["/livox"] = {kT0 + 65};
  for (int k = 0; k < 2; ++k) {
    LaserScan2D s;
    s.timestamp = static_cast<double>(kT0 + 123456789 * (k + 1)) * 1e-9;
    s.angle_min = static_cast<double>(-1.5f);
    s.angle_increment = static_cast<double>(0.25f);
    s.max_range = 30.0f;
    s.ranges = {1.0f, 2.5f, 0.0f, 29.0f + k};
    s.remissions = {5, 6, 7, 8};
    const std::vector<float> ranges = {1.0f, 2.5f, std::numeric_limits<float>::infinity(),
                                       29.0f + k};
    c.messages.push_back(
        {"/scan", kT0 + 123456789 * (k + 1) + 10,
         laser_scan(cdr, kT0 + 123456789 * (k + 1), -1.5f, 0.25f, 30.0f, ranges, s.remissions)});
    c.scans.push_back(s);
  }
  return c;
}

/// Reads every cloud and scan topic of `bag` and compares with the case.
void expect_case(BagReader& bag, const Case& c, const std::string& encoding) {
  ASSERT_EQ(bag.topics().size(), c.topics.size());
  EXPECT_EQ(bag.topics()[0].name, "/chatter");  // sorted by name
  for (const TestTopic& t : c.topics) {
    const BagTopic* topic = bag.find_topic(t.name);
    ASSERT_NE(topic, nullptr) << t.name;
    EXPECT_EQ(topic->type, t.type);
    EXPECT_EQ(topic->encoding, encoding);
    std::uint64_t count = 0;
    for (const TestMessage& m : c.messages) count += m.topic == t.name;
    EXPECT_EQ(topic->message_count, count) << t.name;
  }
  for (const auto& [topic, clouds] : c.clouds) {
    bag.select({topic});
    BagMessage m;
    std::size_t i = 0;
    while (bag.next(m)) {
      ASSERT_LT(i, clouds.size());
      std::int64_t stamp = 0;
      testing::expect_same_cloud(decode_cloud_message(m, bag.path(), &stamp), clouds[i]);
      EXPECT_EQ(stamp, c.stamps.at(topic)[i]);
      ++i;
    }
    EXPECT_EQ(i, clouds.size()) << topic;
  }
  bag.select({"/scan"});
  BagMessage m;
  for (const LaserScan2D& e : c.scans) {
    ASSERT_TRUE(bag.next(m));
    const LaserScan2D s = decode_laser_scan(m, bag.path());
    EXPECT_EQ(s.timestamp, e.timestamp);
    EXPECT_EQ(s.angle_min, e.angle_min);
    EXPECT_EQ(s.angle_increment, e.angle_increment);
    EXPECT_EQ(s.max_range, e.max_range);
    EXPECT_EQ(s.ranges, e.ranges);
    EXPECT_EQ(s.remissions, e.remissions);
  }
  EXPECT_FALSE(bag.next(m));
  // All topics: time order across the whole bag.
  bag.select({});
  std::int64_t last = 0;
  std::size_t n = 0;
  while (bag.next(m)) {
    EXPECT_GE(m.timestamp_ns, last);
    last = m.timestamp_ns;
    ++n;
  }
  EXPECT_EQ(n, c.messages.size());
  EXPECT_FALSE(bag.fault());
}

/// A file in a folder of this test process, removed at exit.
std::string temp_path(const std::string& name) {
  static const scanmatch::testing::TempDir dir;
  return dir.file(name);
}

std::string write_temp(const std::string& name, const std::string& bytes) {
  const std::string path = temp_path(name);
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

/// Reads every message of every topic; used to make faults surface.
std::size_t drain(BagReader& bag) {
  bag.select({});
  BagMessage m;
  std::size_t n = 0;
  while (bag.next(m)) ++n;
  return n;
}

class BagRos1 : public ::testing::TestWithParam<std::string> {};

TEST_P(BagRos1, ReadsBackEveryMessageExactly) {
  const Case c = make_case(false);
  const std::string path =
      write_temp("ros1_" + GetParam() + ".bag", ros1_bag(c.topics, c.messages, GetParam(), 4));
  const auto bag = open_bag(path);
  EXPECT_EQ(bag->format(), "ROS 1 bag");
  expect_case(*bag, c, "ros1");
}

INSTANTIATE_TEST_SUITE_P(BagChunks, BagRos1, ::testing::Values("none", "bz2", "lz4"));

class BagMcap : public ::testing::TestWithParam<std::string> {};

TEST_P(BagMcap, ReadsBackEveryMessageExactly) {
  for (const std::size_t per_chunk : {std::size_t{0}, std::size_t{3}}) {
    if (per_chunk == 0 && GetParam() != "") continue;
    const Case c = make_case(true);
    const auto bag = open_bag_bytes(mcap_file(c.topics, c.messages, GetParam(), per_chunk), "mem");
    EXPECT_EQ(bag->format(), "MCAP");
    expect_case(*bag, c, "cdr");
  }
}

TEST_P(BagMcap, ReadsRos1Messages) {
  const Case c = make_case(false);
  const std::string path =
      write_temp("ros1.mcap", mcap_file(c.topics, c.messages, GetParam(), 2, true));
  expect_case(*open_bag(path), c, "ros1");
}

INSTANTIATE_TEST_SUITE_P(BagChunks, BagMcap, ::testing::Values("", "zstd", "lz4"));

TEST(BagDb3, ReadsBackEveryMessageExactly) {
  const Case c = make_case(true);
  const std::string path = temp_path("bag.db3");
  write_db3(path, c.topics, c.messages);
  const auto bag = open_bag(path);
  EXPECT_EQ(bag->format(), "ROS 2 SQLite bag");
  expect_case(*bag, c, "cdr");
  // A ROS 2 bag folder opens its one .db3 file.
  const fs::path folder = fs::path(temp_path("ros2_bag"));
  fs::create_directories(folder);
  std::ofstream(folder / "metadata.yaml") << "rosbag2_bagfile_information:\n";
  write_db3((folder / "ros2_bag_0.db3").string(), c.topics, c.messages);
  EXPECT_TRUE(is_bag_path(folder.string()));
  EXPECT_EQ(open_bag(folder.string())->topics().size(), c.topics.size());
}

TEST(BagErrors, AbsentTopicIsNamedWithTheCandidates) {
  const Case c = make_case(false);
  const auto bag = open_bag_bytes(ros1_bag(c.topics, c.messages), "x.bag");
  try {
    bag->select({"/nope"});
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("x.bag"), std::string::npos) << what;
    EXPECT_NE(what.find("/nope"), std::string::npos) << what;
    EXPECT_NE(what.find("/points"), std::string::npos) << what;
  }
}

TEST(BagErrors, UnsupportedMessageTypeIsRefused) {
  const Case c = make_case(true);
  const auto bag = open_bag_bytes(mcap_file(c.topics, c.messages, "zstd"), "x.mcap");
  bag->select({"/chatter"});
  BagMessage m;
  ASSERT_TRUE(bag->next(m));
  EXPECT_THROW(decode_cloud_message(m, "x.mcap"), Error);
  EXPECT_THROW(decode_laser_scan(m, "x.mcap"), Error);
  m.type = "sensor_msgs/msg/PointCloud2";  // bytes that do not hold one
  try {
    decode_cloud_message(m, "x.mcap");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("topic /chatter"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("byte"), std::string::npos) << e.what();
  }
}

TEST(BagErrors, UnknownCompressionIsNamed) {
  const Case c = make_case(false);
  try {
    open_bag_bytes(ros1_bag(c.topics, c.messages, "snappy"), "x.bag");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown compression 'snappy'"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("chunk at byte 4117"), std::string::npos) << e.what();
  }
  const Case c2 = make_case(true);
  EXPECT_THROW(open_bag_bytes(mcap_file(c2.topics, c2.messages, "brotli"), "x.mcap"), Error);
}

TEST(BagErrors, PointCloudWhoseSizesDoNotAddUpIsRefused) {
  PointCloud unused;
  for (const bool cdr : {false, true}) {
    BagMessage m;
    m.topic = "/points";
    m.type = "sensor_msgs/PointCloud2";
    m.encoding = cdr ? "cdr" : "ros1";
    m.data = ouster_cloud(cdr, kT0, 0, unused);
    // Shrink the data length word and drop bytes: every prefix must be refused, never crash.
    for (std::size_t cut = 0; cut < m.data.size(); ++cut) {
      BagMessage t = m;
      t.data.resize(cut);
      EXPECT_THROW(decode_cloud_message(t, "x"), Error) << cut;
    }
    EXPECT_NO_THROW(decode_cloud_message(m, "x"));
  }
}

TEST(BagErrors, TruncatedFilesFailWithAnError) {
  const Case c = make_case(false);
  const Case c2 = make_case(true);
  const std::string files[] = {
      ros1_bag(c.topics, c.messages, "none"),    ros1_bag(c.topics, c.messages, "bz2"),
      ros1_bag(c.topics, c.messages, "lz4"),     mcap_file(c2.topics, c2.messages, ""),
      mcap_file(c2.topics, c2.messages, "zstd"), mcap_file(c2.topics, c2.messages, "lz4", 0)};
  for (const std::string& file : files) {
    // Reading stops at MCAP's Data End record; a ROS 1 bag cut before its index is refused
    // (cuts inside the index section can end at a record boundary and go unnoticed).
    std::size_t last = file.size() - 8 - 29;
    if (file.compare(0, 2, "#R") == 0)
      std::memcpy(&last, file.data() + file.find("index_pos=") + 10, 8);
    for (std::size_t cut = 0; cut < file.size(); cut += 1 + cut / 50) {
      try {
        const auto bag = open_bag_bytes(file.substr(0, cut), "cut");
        drain(*bag);
        if (cut < last) ADD_FAILURE() << "no error at cut " << cut << " of " << file.size();
      } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()).rfind("cut", 0), 0u) << e.what();
      }
    }
  }
  // Messages before the fault are delivered, then the error is thrown.
  const std::string file = ros1_bag(c.topics, c.messages, "none", 2);
  std::size_t index_pos = 0;
  std::memcpy(&index_pos, file.data() + file.find("index_pos=") + 10, 8);
  const auto bag = open_bag_bytes(file.substr(0, index_pos - 10), "cut short");
  EXPECT_TRUE(bag->fault());
  bag->select({});
  BagMessage m;
  std::size_t delivered = 0;
  const auto read_all = [&] {
    while (bag->next(m)) ++delivered;
  };
  EXPECT_THROW(read_all(), Error);
  EXPECT_GT(delivered, 0u);
}

TEST(BagErrors, NotABag) {
  EXPECT_THROW(open_bag_bytes("hello world", "x"), Error);
  EXPECT_THROW(open_bag_bytes("", "x"), Error);
  EXPECT_THROW(open_bag_bytes("#ROSBAG V1.2\n", "x"), Error);
  EXPECT_THROW(open_bag(temp_path("missing.bag")), Error);
}

/// Writes the fuzzers' seed files: run with --gtest_also_run_disabled_tests and
/// SCANMATCH_SEED_DIR=fuzz/seeds.
TEST(BagSeeds, DISABLED_WriteFuzzSeeds) {
  const char* dir = std::getenv("SCANMATCH_SEED_DIR");
  ASSERT_NE(dir, nullptr);
  Case c = make_case(false);
  c.messages.resize(5);  // small seeds
  Case c2 = make_case(true);
  c2.messages.resize(5);
  const auto put = [&](const std::string& target, const std::string& name, const std::string& b) {
    fs::create_directories(fs::path(dir) / target);
    // The fuzz targets add the magic themselves.
    std::ofstream(fs::path(dir) / target / name, std::ios::binary)
        << b.substr(target == "fuzz_mcap" ? 8 : 13);
  };
  for (const char* z : {"none", "bz2", "lz4"})
    put("fuzz_ros1_bag", z, ros1_bag(c.topics, c.messages, z, 2));
  put("fuzz_mcap", "plain", mcap_file(c2.topics, c2.messages, "", 0));
  put("fuzz_mcap", "chunks", mcap_file(c2.topics, c2.messages, "", 2));
  put("fuzz_mcap", "zstd", mcap_file(c2.topics, c2.messages, "zstd", 2));
  put("fuzz_mcap", "lz4", mcap_file(c2.topics, c2.messages, "lz4", 2));
  put("fuzz_mcap", "ros1", mcap_file(c.topics, c.messages, "", 2, true));
}

}  // namespace
}  // namespace scanmatch
