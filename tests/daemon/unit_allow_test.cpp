#include "trajroi/daemon/unit_allow.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

namespace {

using trajroi::daemon::DaemonConfig;
using trajroi::daemon::PoseSource;
using trajroi::daemon::UnitAllowLists;

bool has(const std::vector<std::string>& list, const std::string& entry) {
  return std::find(list.begin(), list.end(), entry) != list.end();
}

TEST(UnitAllow, TheSensorTheLcmGroupAndThisHostsAddressesAreAllowedAndNothingElse) {
  DaemonConfig c;
  c.lidar.sensor_address = "10.0.0.100";
  const UnitAllowLists l = trajroi::daemon::unit_allow_lists(c, "udpm://239.255.0.9:7700?ttl=1", {"192.0.2.2"});
  EXPECT_EQ(l.ip_allow, (std::vector<std::string>{"localhost", "239.255.0.9", "192.0.2.2", "10.0.0.100"}));
  EXPECT_TRUE(l.problems.empty());
  const std::string drop_in = trajroi::daemon::unit_drop_in(l, "/etc/trajroi/trajroid.yaml");
  // The unit's own list is reset first, then each entry follows.
  EXPECT_NE(drop_in.find("[Service]\nIPAddressAllow=\nIPAddressAllow=localhost\nIPAddressAllow=239.255.0.9\n"),
            std::string::npos)
      << drop_in;
  EXPECT_NE(drop_in.find("# allows the LiDAR at 10.0.0.100 (lidar.sensor_address)"), std::string::npos) << drop_in;
  const auto args = trajroi::daemon::set_property_arguments(l, "trajroid.service");
  EXPECT_EQ(std::vector<std::string>(args.begin(), args.begin() + 6),
            (std::vector<std::string>{"systemctl", "set-property", "--runtime", "trajroid.service",
                                      "IPAddressAllow=", "IPAddressAllow=localhost"}));
}

TEST(UnitAllow, AnySenderAdmitsThePrivateAndLinkLocalRangesAndAnotherProviderNoGroup) {
  DaemonConfig c;
  const UnitAllowLists l = trajroi::daemon::unit_allow_lists(c, "memq://", {"192.0.2.2"});
  EXPECT_EQ(l.ip_allow,
            (std::vector<std::string>{"localhost", "10.0.0.0/8", "172.16.0.0/12", "192.168.0.0/16", "169.254.0.0/16"}));
}

TEST(UnitAllow, SerialDevicesAreAllowedByNodeAndClassALinkByItsNodeAMissingOneIsAProblem) {
  const auto link = std::filesystem::temp_directory_path() / ("trajroi_unit_allow_" + std::to_string(::getpid()));
  std::filesystem::remove(link);
  std::filesystem::create_symlink("/dev/null", link);
  DaemonConfig c;
  c.gnss.device = link.string();
  c.imu.device = "/dev/trajroi-no-such-device";
  const UnitAllowLists l = trajroi::daemon::unit_allow_lists(c, "udpm://239.255.76.67:7667?ttl=0", {});
  std::filesystem::remove(link);
  EXPECT_TRUE(has(l.device_allow, "/dev/null rw")) << "the link's node, not the link (systemd takes /dev paths)";
  EXPECT_TRUE(has(l.device_allow, "char-mem rw")) << "/dev/null's class in /proc/devices";
  EXPECT_FALSE(has(l.device_allow, link.string() + " rw"));
  ASSERT_EQ(l.problems.size(), 1u);
  EXPECT_NE(l.problems[0].find("imu.device /dev/trajroi-no-such-device does not exist"), std::string::npos);

  // A stream the pose source does not read is not allowed.
  c.pose_source = PoseSource::kLcm;
  EXPECT_TRUE(trajroi::daemon::unit_allow_lists(c, "udpm://239.255.76.67:7667?ttl=0", {}).device_allow.empty());
}

// gnss.corrections under the unit's IP filter: the caster's address is admitted (a name
// resolved at the unit's start), a radio's device is allowed like the GNSS port, a UDP
// base station, whose address is not known, is said.
TEST(UnitAllow, TheCorrectionsServerAndARadioAreAllowedAUdpBaseIsSaid) {
  DaemonConfig c;
  c.lidar.sensor_address = "10.0.0.100";
  c.gnss_corrections.url = "ntrip://rover:s3cret@203.0.113.7:2101/MOUNT";
  UnitAllowLists l = trajroi::daemon::unit_allow_lists(c, "memq://", {});
  EXPECT_EQ(l.ip_allow, (std::vector<std::string>{"localhost", "10.0.0.100", "203.0.113.7"}));
  ASSERT_FALSE(l.reasons.empty());
  EXPECT_EQ(l.reasons.back(), "the corrections' server ntrip://rover:***@203.0.113.7:2101/MOUNT at 203.0.113.7");
  c.gnss_corrections.url = "tcp://localhost:9001";  // resolved: 127.0.0.1
  l = trajroi::daemon::unit_allow_lists(c, "memq://", {});
  EXPECT_TRUE(has(l.ip_allow, "127.0.0.1"));
  c.gnss_corrections.url = "serial:///dev/null?baud=57600";  // a character device standing in for the radio
  l = trajroi::daemon::unit_allow_lists(c, "memq://", {});
  EXPECT_TRUE(has(l.device_allow, "/dev/null rw"));
  EXPECT_TRUE(has(l.device_allow, "char-mem rw"));
  c.gnss_corrections.url = "udp://:9000";
  l = trajroi::daemon::unit_allow_lists(c, "memq://", {});
  ASSERT_EQ(l.problems.size(), 1u);
  EXPECT_NE(l.problems[0].find("the base station's address is not known here"), std::string::npos) << l.problems[0];
}

}  // namespace
