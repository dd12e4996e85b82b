// The other Velodyne models without captures: the Puck Hi-Res geometry against its manual's
// table, a configuration or a stream that disagrees with the packets named, and the
// calibration files of 32 lasers in both forms (velodyne/nebula YAML, VeloView XML).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "model_replay.hpp"
#include "packet_builder.hpp"

namespace trajroi::vlp16 {
namespace {

using namespace model_test;

// Puck Hi-Res (0x24): its manual's vertical angles (±10°, 1.33° apart) and vertical offsets,
// through a packet of its product id: every channel at 10 m, azimuth 0.
TEST(ModelGeometry, PuckHiResIsItsManualsTable) {
  constexpr double kAngleDeg[16] = {-10.00, 0.67, -8.67, 2.00, -7.33, 3.33, -6.00, 4.67,
                                    -4.67,  6.00, -3.33, 7.33, -2.00, 8.67, -0.67, 10.00};
  constexpr double kOffset_mm[16] = {7.4, -0.9, 6.5, -1.8, 5.5, -2.7, 4.6, -3.7,
                                     3.7, -4.6, 2.7, -5.5, 1.8, -6.5, 0.9, -7.4};
  auto packet = make_packet(0, 40, ReturnMode::kStrongest, kProductPuckHiRes);
  for (std::size_t block = 0; block < kBlocks; ++block)
    for (std::size_t channel = 0; channel < 32; ++channel)
      set_return(packet, block, channel, 5000, 100);  // 10 m
  StreamOptions options = auto_model();
  StreamDecoder stream(Calibration::vlp16_default(), options);
  const PacketDecoder* decoder = stream.decoder_for(packet);
  ASSERT_NE(decoder, nullptr);
  EXPECT_EQ(decoder->model(), Model::kPuckHiRes);
  std::vector<Point> points;
  decoder->decode(packet, points);
  ASSERT_EQ(points.size(), 384u);
  for (std::size_t i = 0; i < 16; ++i) {
    const Point& p = points[i];
    const double w = kAngleDeg[p.laser] * kDeg, v = kOffset_mm[p.laser] / 1000.0;
    EXPECT_NEAR(p.z, 10.0 * std::sin(w) + v * std::cos(w), 1e-5) << int{p.laser};
    EXPECT_NEAR(std::hypot(p.x, p.y), 10.0 * std::cos(w) - v * std::sin(w), 1e-5) << int{p.laser};
  }
}

// lidar.model names one model: another model's packets are dropped, counted and named; told
// from the packets, a second model in the same stream is.
TEST(ModelDetection, DisagreeingPacketsAreNamedAndDropped) {
  Collector sink;
  StreamOptions fixed;  // lidar.model: vlp16
  StreamDecoder vlp16(Calibration::vlp16_default(), fixed);
  const auto packet = [](std::uint32_t i, std::uint8_t product, std::uint32_t period_us) {
    return make_packet(static_cast<std::uint16_t>(i * 480 % 36000), 40, ReturnMode::kStrongest, product,
                       100'000 + i * period_us);
  };
  for (std::uint32_t i = 0; i < 5; ++i)
    vlp16.on_data_packet(packet(i, kProductVlp32c, 664), std::int64_t{i} * 664'000, sink);
  EXPECT_EQ(vlp16.counters().rejected[static_cast<std::size_t>(PacketError::kUnsupportedProduct)], 5u);
  EXPECT_EQ(vlp16.model_check().reason(),
            "product id 0x28 (VLP-32C) sends VLP-32C packets, but lidar.model is vlp16: dropped (set lidar.model: "
            "vlp32c, or auto)");

  StreamDecoder detect(Calibration::vlp16_default(), auto_model());
  for (std::uint32_t i = 0; i < 5; ++i)
    detect.on_data_packet(packet(i, kProductVlp16, 1327), std::int64_t{i} * 1'327'000, sink);
  for (std::uint32_t i = 5; i < 8; ++i)
    detect.on_data_packet(packet(i, kProductVlp32c, 1327), std::int64_t{i} * 1'327'000, sink);
  EXPECT_EQ(detect.counters().decoded_packets, 5u);
  EXPECT_EQ(detect.counters().rejected[static_cast<std::size_t>(PacketError::kUnsupportedProduct)], 3u);
  EXPECT_EQ(detect.model_check().model(), Model::kVlp16);
  EXPECT_EQ(detect.model_check().reason(),
            "the sensor's packets changed model mid-run, from VLP-16 to product id 0x28 (VLP-32C): the new model's "
            "packets are dropped");
}

// A 32-laser calibration YAML (the velodyne/nebula form) reads, and its number of lasers must
// be the model's.
TEST(ModelGeometry, ThirtyTwoLaserCalibrationsReadAndMustFitTheModel) {
  std::string yaml = "lasers:\n";
  for (int i = 0; i < 32; ++i) {
    yaml += "  - {laser_id: " + std::to_string(i) + ", vert_correction: " + std::to_string(0.01 * (i - 16)) +
            ", rot_correction: 0.0}\n";
  }
  yaml += "num_lasers: 32\n";
  const Calibration c = parse_calibration_yaml(yaml, "vlp32.yaml");
  EXPECT_EQ(c.laser_count, 32u);
  EXPECT_DOUBLE_EQ(c.lasers[31].vert_angle_rad, 0.15);
  EXPECT_NO_THROW(PacketDecoder(c, {}, Model::kVlp32c));
  EXPECT_THROW(PacketDecoder(c, {}, Model::kVlp16), std::invalid_argument);
  try {
    (void)parse_calibration_yaml(yaml.substr(0, yaml.size() - 3) + "16\n", "vlp32.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "vlp32.yaml:34: 'num_lasers' says 16 but 'lasers' has 32 entries");
  }
}

// VeloView's XML (db.xml): degrees and centimetres, as the ROS driver's gen_calibration.py
// reads them; a laser missing an element is named with its line.
TEST(ModelGeometry, VeloViewXmlCalibrationsRead) {
  std::string xml =
      "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"yes\" ?>\n<!DOCTYPE boost_serialization>\n"
      "<boost_serialization signature=\"serialization::archive\" version=\"4\">\n<DB class_id=\"0\">\n"
      "<distLSB_>0.4</distLSB_>\n<points_ class_id=\"5\" tracking_level=\"0\" version=\"0\">\n"
      "<count>32</count>\n<item_version>1</item_version>\n";
  constexpr double kVertical[32] = {-25.0,  -1.0,  -1.667, -15.639, -11.31, 0.0,   -0.667, -8.843,
                                    -7.254, 0.333, -0.333, -6.148,  -5.333, 1.333, 0.667,  -4.0,
                                    -4.667, 1.667, 1.0,    -3.667,  -3.333, 3.333, 2.333,  -2.667,
                                    -3.0,   7.0,   4.667,  -2.333,  -2.0,   15.0,  10.333, -1.333};
  constexpr double kRotation[32] = {-1.4, 4.2,  -1.4, 1.4,  -1.4, 1.4,  -4.2, 1.4,  -1.4, 4.2,  -1.4,
                                    1.4,  -4.2, 1.4,  -4.2, 1.4,  -1.4, 4.2,  -1.4, 4.2,  -4.2, 1.4,
                                    -1.4, 1.4,  -1.4, 1.4,  -1.4, 4.2,  -4.2, 1.4,  -1.4, 1.4};
  for (int i = 0; i < 32; ++i) {
    char item[400];
    std::snprintf(
        item, sizeof item,
        "<item class_id=\"6\" tracking_level=\"0\" version=\"1\">\n<px class_id=\"7\">\n<id_>%d</id_>\n"
        "<rotCorrection_>%g</rotCorrection_>\n<vertCorrection_>%g</vertCorrection_>\n"
        "<distCorrection_>%d</distCorrection_>\n<distCorrectionX_>0</distCorrectionX_>\n"
        "<vertOffsetCorrection_>0</vertOffsetCorrection_>\n<horizOffsetCorrection_>0</horizOffsetCorrection_>\n"
        "</px>\n</item>\n",
        i, kRotation[i], kVertical[i], i == 3 ? 12 : 0);
    xml += item;
  }
  xml += "</points_>\n</DB>\n</boost_serialization>\n";
  ASSERT_TRUE(looks_like_calibration_xml(xml));
  const Calibration c = parse_calibration_file(xml, "VLP-32c.xml");
  const Calibration manual = Calibration::for_model(Model::kVlp32c);
  ASSERT_EQ(c.laser_count, 32u);
  for (std::size_t i = 0; i < 32; ++i) {
    EXPECT_NEAR(c.lasers[i].vert_angle_rad, manual.lasers[i].vert_angle_rad, 1e-12) << i;
    EXPECT_NEAR(c.lasers[i].rot_correction_rad, manual.lasers[i].rot_correction_rad, 1e-12) << i;
  }
  EXPECT_DOUBLE_EQ(c.lasers[3].dist_correction_m, 0.12);  // 12 cm
  // Laser 5's <vertCorrection_> gone: named with its line.
  const std::size_t cut = xml.find("<vertCorrection_>0</vertCorrection_>");
  ASSERT_NE(cut, std::string::npos);
  std::string broken = xml;
  broken.erase(cut, std::string("<vertCorrection_>0</vertCorrection_>").size());
  try {
    (void)parse_calibration_file(broken, "VLP-32c.xml");
    ADD_FAILURE() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "VLP-32c.xml:65: laser entry 5 has no <vertCorrection_>");  // its <px> line
  }
}

}  // namespace
}  // namespace trajroi::vlp16
