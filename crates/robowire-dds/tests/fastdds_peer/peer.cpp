// A Fast DDS 2.9 peer for robowire-dds's interoperability tests (../it/fastdds.rs), built by the
// test into the cargo target directory with fastddsgen's type support of unitree_go.idl and
// unitree_hg.idl.
//
//   peer pub      key=value...   a writer: waits for a matched reader, writes `count` samples
//   peer sub      key=value...   a reader: prints each sample, stops after `expect` of them
//   peer discover key=value...   a reader of Go2 LowCmd_ (rt/lowcmd) and a writer of Go2
//                                LowState_ (rt/lowstate) that write nothing: match counts only
//
// Keys (defaults): domain (0), type (go2_lowcmd | go2_lowstate | hg_lowstate), topic (rt/lowcmd
// or rt/lowstate by type), reliability (reliable | besteffort), durability (volatile |
// transient_local), depth (1), count (10), period_ms (20), wait_match_ms (10000), settle_ms
// (200), linger_ms (2000), expect (0: until `seconds`), seconds (30: the peer's whole life).
//
// Every line on stdout is one JSON object with an "event": "ready" (the participant's GUID
// prefix), "publication_matched" / "subscription_matched" (Fast DDS's matched statuses, with
// the remote endpoint's GUID), "offered_incompatible_qos" / "requested_incompatible_qos",
// "written" (a sample's index and CRC), "sample" (a received sample's fields, its CRC and
// whether the CRC Unitree's algorithm computes here over the struct image agrees) and a final
// "summary". The peer stops early, cleanly (deleting its participant, which Fast DDS announces),
// when its standard input closes.
//
// Samples written are a function of their index i (fill_* below, mirrored by the test), their
// CRC computed here: Unitree's CRC-32/MPEG-2 over the zero-padded C struct image (spec
// unitree-lowlevel §3, §4), an implementation independent of robowire's.
//
// The participant uses UDPv4 only (no shared memory, which Fast DDS would otherwise use between
// two processes on one host) with a 1472-byte maximum message size (an Ethernet datagram): the
// 2 KB HG LowState_ goes as DATA_FRAG.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <unistd.h>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include "unitree_goPubSubTypes.h"
#include "unitree_hgPubSubTypes.h"

using namespace eprosima::fastdds::dds;
namespace go = unitree_go::msg::dds_;
namespace hg = unitree_hg::msg::dds_;

// ---------------------------------------------------------------------------------------------
// Output: one JSON object per line, from any thread.

static std::mutex out_lock;

static void emit(const std::string& line)
{
  std::lock_guard<std::mutex> g(out_lock);
  std::fputs(line.c_str(), stdout);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

// A JSON object built field by field.
class Json
{
public:
  explicit Json(const char* event) { s_ << "{\"event\":\"" << event << "\""; }
  Json& num(const char* k, double v)
  {
    char b[64];
    std::snprintf(b, sizeof b, "%.9g", v);
    key(k) << b;
    return *this;
  }
  Json& integer(const char* k, long long v)
  {
    key(k) << v;
    return *this;
  }
  Json& boolean(const char* k, bool v)
  {
    key(k) << (v ? "true" : "false");
    return *this;
  }
  Json& str(const char* k, const std::string& v)
  {
    key(k) << '"' << v << '"';
    return *this;
  }
  template <typename It>
  Json& nums(const char* k, It begin, It end)
  {
    key(k) << '[';
    for (It i = begin; i != end; ++i) {
      char b[64];
      std::snprintf(b, sizeof b, "%.9g", static_cast<double>(*i));
      s_ << (i == begin ? "" : ",") << b;
    }
    s_ << ']';
    return *this;
  }
  template <typename C>
  Json& nums(const char* k, const C& c)
  {
    return nums(k, std::begin(c), std::end(c));
  }
  std::string done() { return s_.str() + "}"; }
  void print() { emit(done()); }

private:
  std::ostream& key(const char* k) { return s_ << ",\"" << k << "\":"; }
  std::ostringstream s_;
};

static std::string hex(const uint8_t* p, size_t n)
{
  static const char* digits = "0123456789abcdef";
  std::string s;
  for (size_t i = 0; i < n; i++) {
    s += digits[p[i] >> 4];
    s += digits[p[i] & 15];
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Unitree's CRC over the C struct images (spec unitree-lowlevel §3, §4, §7).

// Unitree's crc32_core: CRC-32/MPEG-2 over 32-bit words, each most significant bit first.
static uint32_t crc32_core(const uint32_t* words, size_t count)
{
  uint32_t crc = 0xFFFFFFFFu;
  const uint32_t poly = 0x04C11DB7u;
  for (size_t i = 0; i < count; i++) {
    uint32_t data = words[i];
    for (uint32_t bit = 1u << 31; bit != 0; bit >>= 1) {
      if (crc & 0x80000000u) {
        crc = (crc << 1) ^ poly;
      } else {
        crc <<= 1;
      }
      if (data & bit) crc ^= poly;
    }
  }
  return crc;
}

// The CRC of an image: every word but the last (the crc field itself). x86-64 and aarch64 are
// little-endian, as the image is.
template <typename Image>
static uint32_t image_crc(const Image& img)
{
  static_assert(sizeof(Image) % 4 == 0, "an image is whole words");
  uint32_t words[sizeof(Image) / 4];
  std::memcpy(words, &img, sizeof(Image));
  return crc32_core(words, sizeof(Image) / 4 - 1);
}

// Natural C alignment, as Unitree's C++ message types; zeroed with memset (padding included).
struct GoMotorCmdImg { uint8_t mode; float q, dq, tau, kp, kd; uint32_t reserve[3]; };
struct GoBmsCmdImg { uint8_t off; uint8_t reserve[3]; };
struct GoLowCmdImg {
  uint8_t head[2]; uint8_t level_flag; uint8_t frame_reserve; uint32_t sn[2]; uint32_t version[2];
  uint16_t bandwidth; GoMotorCmdImg motor_cmd[20]; GoBmsCmdImg bms_cmd; uint8_t wireless_remote[40];
  uint8_t led[12]; uint8_t fan[2]; uint8_t gpio; uint32_t reserve; uint32_t crc;
};
struct GoImuImg { float quaternion[4], gyroscope[3], accelerometer[3], rpy[3]; uint8_t temperature; };
struct GoMotorStateImg {
  uint8_t mode; float q, dq, ddq, tau_est, q_raw, dq_raw, ddq_raw; uint8_t temperature; uint32_t lost;
  uint32_t reserve[2];
};
struct GoBmsStateImg {
  uint8_t version_high, version_low, status, soc; int32_t current; uint16_t cycle; uint8_t bq_ntc[2];
  uint8_t mcu_ntc[2]; uint16_t cell_vol[15];
};
struct GoLowStateImg {
  uint8_t head[2]; uint8_t level_flag; uint8_t frame_reserve; uint32_t sn[2]; uint32_t version[2];
  uint16_t bandwidth; GoImuImg imu_state; GoMotorStateImg motor_state[20]; GoBmsStateImg bms_state;
  int16_t foot_force[4]; int16_t foot_force_est[4]; uint32_t tick; uint8_t wireless_remote[40];
  uint8_t bit_flag; float adc_reel; uint8_t temperature_ntc1, temperature_ntc2; float power_v, power_a;
  uint16_t fan_frequency[4]; uint32_t reserve; uint32_t crc;
};
struct HgImuImg { float quaternion[4], gyroscope[3], accelerometer[3], rpy[3]; int16_t temperature; };
struct HgMotorStateImg {
  uint8_t mode; float q, dq, ddq, tau_est; int16_t temperature[2]; float vol; uint32_t sensor[2];
  uint32_t motorstate; uint32_t reserve[4];
};
struct HgLowStateImg {
  uint32_t version[2]; uint8_t mode_pr, mode_machine; uint32_t tick; HgImuImg imu_state;
  HgMotorStateImg motor_state[35]; uint8_t wireless_remote[40]; uint32_t reserve[4]; uint32_t crc;
};
static_assert(sizeof(GoMotorCmdImg) == 36, "spec 3.2");
static_assert(sizeof(GoLowCmdImg) == 812, "spec 3.1");
static_assert(offsetof(GoLowCmdImg, motor_cmd) == 24 && offsetof(GoLowCmdImg, reserve) == 804, "spec 3.1");
static_assert(sizeof(GoImuImg) == 56 && sizeof(GoMotorStateImg) == 48 && sizeof(GoBmsStateImg) == 44, "3.4");
static_assert(sizeof(GoLowStateImg) == 1180, "spec 3.3");
static_assert(offsetof(GoLowStateImg, bms_state) == 1040 && offsetof(GoLowStateImg, adc_reel) == 1148, "3.3");
static_assert(offsetof(GoLowStateImg, fan_frequency) == 1164 && offsetof(GoLowStateImg, crc) == 1176, "3.3");
static_assert(sizeof(HgMotorStateImg) == 56 && sizeof(HgImuImg) == 56, "spec 7");
static_assert(sizeof(HgLowStateImg) == 2092 && offsetof(HgLowStateImg, motor_state) == 72, "spec 7");
static_assert(offsetof(HgLowStateImg, wireless_remote) == 2032 && offsetof(HgLowStateImg, crc) == 2088, "7");

template <typename Dst, typename Src>
static void copy_array(Dst& dst, const Src& src)
{
  for (size_t i = 0; i < sizeof(dst) / sizeof(dst[0]); i++) dst[i] = src[i];
}

template <typename Image>
static void zero(Image& img)
{
  std::memset(static_cast<void*>(&img), 0, sizeof(Image));
}

static GoLowCmdImg image_of(const go::LowCmd_& m)
{
  GoLowCmdImg i;
  zero(i);
  copy_array(i.head, m.head());
  i.level_flag = m.level_flag();
  i.frame_reserve = m.frame_reserve();
  copy_array(i.sn, m.sn());
  copy_array(i.version, m.version());
  i.bandwidth = m.bandwidth();
  for (size_t k = 0; k < 20; k++) {
    const go::MotorCmd_& c = m.motor_cmd()[k];
    GoMotorCmdImg& o = i.motor_cmd[k];
    o.mode = c.mode();
    o.q = c.q();
    o.dq = c.dq();
    o.tau = c.tau();
    o.kp = c.kp();
    o.kd = c.kd();
    copy_array(o.reserve, c.reserve());
  }
  i.bms_cmd.off = m.bms_cmd().off();
  copy_array(i.bms_cmd.reserve, m.bms_cmd().reserve());
  copy_array(i.wireless_remote, m.wireless_remote());
  copy_array(i.led, m.led());
  copy_array(i.fan, m.fan());
  i.gpio = m.gpio();
  i.reserve = m.reserve();
  i.crc = m.crc();
  return i;
}

static GoLowStateImg image_of(const go::LowState_& m)
{
  GoLowStateImg i;
  zero(i);
  copy_array(i.head, m.head());
  i.level_flag = m.level_flag();
  i.frame_reserve = m.frame_reserve();
  copy_array(i.sn, m.sn());
  copy_array(i.version, m.version());
  i.bandwidth = m.bandwidth();
  const go::IMUState_& imu = m.imu_state();
  copy_array(i.imu_state.quaternion, imu.quaternion());
  copy_array(i.imu_state.gyroscope, imu.gyroscope());
  copy_array(i.imu_state.accelerometer, imu.accelerometer());
  copy_array(i.imu_state.rpy, imu.rpy());
  i.imu_state.temperature = imu.temperature();
  for (size_t k = 0; k < 20; k++) {
    const go::MotorState_& s = m.motor_state()[k];
    GoMotorStateImg& o = i.motor_state[k];
    o.mode = s.mode();
    o.q = s.q();
    o.dq = s.dq();
    o.ddq = s.ddq();
    o.tau_est = s.tau_est();
    o.q_raw = s.q_raw();
    o.dq_raw = s.dq_raw();
    o.ddq_raw = s.ddq_raw();
    o.temperature = s.temperature();
    o.lost = s.lost();
    copy_array(o.reserve, s.reserve());
  }
  const go::BmsState_& b = m.bms_state();
  i.bms_state.version_high = b.version_high();
  i.bms_state.version_low = b.version_low();
  i.bms_state.status = b.status();
  i.bms_state.soc = b.soc();
  i.bms_state.current = b.current();
  i.bms_state.cycle = b.cycle();
  copy_array(i.bms_state.bq_ntc, b.bq_ntc());
  copy_array(i.bms_state.mcu_ntc, b.mcu_ntc());
  copy_array(i.bms_state.cell_vol, b.cell_vol());
  copy_array(i.foot_force, m.foot_force());
  copy_array(i.foot_force_est, m.foot_force_est());
  i.tick = m.tick();
  copy_array(i.wireless_remote, m.wireless_remote());
  i.bit_flag = m.bit_flag();
  i.adc_reel = m.adc_reel();
  i.temperature_ntc1 = m.temperature_ntc1();
  i.temperature_ntc2 = m.temperature_ntc2();
  i.power_v = m.power_v();
  i.power_a = m.power_a();
  copy_array(i.fan_frequency, m.fan_frequency());
  i.reserve = m.reserve();
  i.crc = m.crc();
  return i;
}

static HgLowStateImg image_of(const hg::LowState_& m)
{
  HgLowStateImg i;
  zero(i);
  copy_array(i.version, m.version());
  i.mode_pr = m.mode_pr();
  i.mode_machine = m.mode_machine();
  i.tick = m.tick();
  const hg::IMUState_& imu = m.imu_state();
  copy_array(i.imu_state.quaternion, imu.quaternion());
  copy_array(i.imu_state.gyroscope, imu.gyroscope());
  copy_array(i.imu_state.accelerometer, imu.accelerometer());
  copy_array(i.imu_state.rpy, imu.rpy());
  i.imu_state.temperature = imu.temperature();
  for (size_t k = 0; k < 35; k++) {
    const hg::MotorState_& s = m.motor_state()[k];
    HgMotorStateImg& o = i.motor_state[k];
    o.mode = s.mode();
    o.q = s.q();
    o.dq = s.dq();
    o.ddq = s.ddq();
    o.tau_est = s.tau_est();
    copy_array(o.temperature, s.temperature());
    o.vol = s.vol();
    copy_array(o.sensor, s.sensor());
    o.motorstate = s.motorstate();
    copy_array(o.reserve, s.reserve());
  }
  copy_array(i.wireless_remote, m.wireless_remote());
  copy_array(i.reserve, m.reserve());
  i.crc = m.crc();
  return i;
}

// ---------------------------------------------------------------------------------------------
// Samples as a function of their index (the test's fill_* functions are the same).

static void fill(go::LowCmd_& m, uint32_t i)
{
  m.head({0xFE, 0xEF});
  m.level_flag(0xFF);
  m.sn({i, 7});
  m.version({1, 2});
  m.bandwidth(0x3A);
  for (uint32_t k = 0; k < 20; k++) {
    go::MotorCmd_& c = m.motor_cmd()[k];
    c.mode(1);
    c.q(0.25f * k + i);
    c.dq(-0.5f * k);
    c.tau(0.125f * k);
    c.kp(20.0f + k);
    c.kd(0.5f);
    c.reserve({k, 0, 0});
  }
  for (uint32_t j = 0; j < 40; j++) m.wireless_remote()[j] = static_cast<uint8_t>(j);
  for (uint32_t j = 0; j < 12; j++) m.led()[j] = static_cast<uint8_t>(2 * j);
  m.fan({1, 2});
  m.gpio(3);
  m.reserve(i);
  m.crc(image_crc(image_of(m)));
}

static void fill(go::LowState_& m, uint32_t i)
{
  m.head({0xFE, 0xEF});
  m.level_flag(0xFF);
  m.sn({i, 0});
  m.version({1, 2});
  go::IMUState_& imu = m.imu_state();
  imu.quaternion({1.0f, 0.0f, 0.0f, 0.0f});
  imu.gyroscope({0.5f, -0.5f, 0.25f});
  imu.accelerometer({0.0f, 0.0f, 9.75f});
  imu.rpy({0.125f, 0.0f, -0.125f});
  imu.temperature(40);
  for (uint32_t k = 0; k < 20; k++) {
    go::MotorState_& s = m.motor_state()[k];
    s.mode(1);
    s.q(0.25f * k + i);
    s.dq(0.5f);
    s.tau_est(-0.25f * k);
    s.q_raw(0.25f * k + i);
    s.dq_raw(0.5f);
    s.temperature(static_cast<uint8_t>(30 + k));
    s.lost(k);
  }
  go::BmsState_& b = m.bms_state();
  b.version_high(1);
  b.version_low(2);
  b.status(3);
  b.soc(88);
  b.current(-1500);
  b.cycle(12);
  b.bq_ntc({25, 26});
  b.mcu_ntc({30, 31});
  for (uint16_t j = 0; j < 15; j++) b.cell_vol()[j] = static_cast<uint16_t>(3600 + j);
  m.foot_force({10, 20, 30, 40});
  m.foot_force_est({-1, -2, -3, -4});
  m.tick(1000 + i);
  for (uint32_t j = 0; j < 40; j++) m.wireless_remote()[j] = static_cast<uint8_t>(255 - j);
  m.bit_flag(0x80);
  m.adc_reel(1.5f);
  m.temperature_ntc1(200);
  m.temperature_ntc2(41);
  m.power_v(28.5f);
  m.power_a(1.25f);
  m.fan_frequency({1000, 2000, 40000, 0});
  m.reserve(i);
  m.crc(image_crc(image_of(m)));
}

static void fill(hg::LowState_& m, uint32_t i)
{
  m.version({3, 4});
  m.mode_pr(0);
  m.mode_machine(5);
  m.tick(1000 + i);
  hg::IMUState_& imu = m.imu_state();
  imu.quaternion({1.0f, 0.0f, 0.0f, 0.0f});
  imu.gyroscope({0.5f, -0.5f, 0.25f});
  imu.accelerometer({0.0f, 0.0f, 9.75f});
  imu.rpy({0.125f, 0.0f, -0.125f});
  imu.temperature(-5);
  for (uint32_t k = 0; k < 35; k++) {
    hg::MotorState_& s = m.motor_state()[k];
    s.mode(1);
    s.q(0.25f * k + i);
    s.dq(0.5f);
    s.tau_est(-0.25f * k);
    s.temperature({static_cast<int16_t>(30 + k), static_cast<int16_t>(-static_cast<int>(k))});
    s.vol(24.5f);
    s.sensor({k, 2 * k});
    s.motorstate(3 * k);
    s.reserve({0, 0, 0, i});
  }
  for (uint32_t j = 0; j < 40; j++) m.wireless_remote()[j] = static_cast<uint8_t>(j + 1);
  m.reserve({i, 1, 2, 3});
  m.crc(image_crc(image_of(m)));
}

// ---------------------------------------------------------------------------------------------
// A received sample's fields.

static Json& with_crc(Json& j, uint32_t received, uint32_t computed)
{
  return j.integer("crc", received).integer("crc_computed", computed).boolean("crc_ok", received == computed);
}

static std::string describe(const go::LowCmd_& m)
{
  Json j("sample");
  j.str("type", "go2_lowcmd").nums("head", m.head()).integer("level_flag", m.level_flag());
  j.nums("sn", m.sn()).nums("version", m.version()).integer("bandwidth", m.bandwidth());
  float q[20], dq[20], tau[20], kp[20], kd[20];
  int mode[20];
  for (size_t k = 0; k < 20; k++) {
    const go::MotorCmd_& c = m.motor_cmd()[k];
    mode[k] = c.mode();
    q[k] = c.q();
    dq[k] = c.dq();
    tau[k] = c.tau();
    kp[k] = c.kp();
    kd[k] = c.kd();
  }
  j.nums("mode", mode).nums("q", q).nums("dq", dq).nums("tau", tau).nums("kp", kp).nums("kd", kd);
  j.nums("wireless_remote", m.wireless_remote()).nums("led", m.led()).nums("fan", m.fan());
  j.integer("gpio", m.gpio()).integer("reserve", m.reserve());
  return with_crc(j, m.crc(), image_crc(image_of(m))).done();
}

static std::string describe(const go::LowState_& m)
{
  Json j("sample");
  j.str("type", "go2_lowstate").integer("tick", m.tick()).integer("reserve", m.reserve());
  float q[20];
  int temperature[20];
  for (size_t k = 0; k < 20; k++) {
    q[k] = m.motor_state()[k].q();
    temperature[k] = m.motor_state()[k].temperature();
  }
  j.nums("q", q).nums("temperature", temperature).nums("quaternion", m.imu_state().quaternion());
  j.integer("soc", m.bms_state().soc()).nums("foot_force", m.foot_force()).num("power_v", m.power_v());
  return with_crc(j, m.crc(), image_crc(image_of(m))).done();
}

static std::string describe(const hg::LowState_& m)
{
  Json j("sample");
  j.str("type", "hg_lowstate").integer("tick", m.tick()).integer("mode_machine", m.mode_machine());
  float q[35], tau_est[35];
  int temperature[35];
  for (size_t k = 0; k < 35; k++) {
    q[k] = m.motor_state()[k].q();
    tau_est[k] = m.motor_state()[k].tau_est();
    temperature[k] = m.motor_state()[k].temperature()[0];
  }
  j.nums("q", q).nums("tau_est", tau_est).nums("temperature", temperature);
  j.nums("wireless_remote", m.wireless_remote()).nums("reserve", m.reserve());
  return with_crc(j, m.crc(), image_crc(image_of(m))).done();
}

// ---------------------------------------------------------------------------------------------
// Endpoints of one type, behind one interface.

struct Endpoint
{
  virtual ~Endpoint() = default;
  virtual TopicDataType* type() = 0;
  // Writes sample `index`; its CRC, or -1 when the write failed.
  virtual long long write(DataWriter* w, uint32_t index) = 0;
  // Takes every sample there is, printing each; how many.
  virtual int take(DataReader* r) = 0;
};

template <typename M, typename PubSub>
struct Typed : Endpoint
{
  TopicDataType* type() override { return new PubSub(); }
  long long write(DataWriter* w, uint32_t index) override
  {
    M m;
    fill(m, index);
    return w->write(&m) ? static_cast<long long>(m.crc()) : -1;
  }
  int take(DataReader* r) override
  {
    int n = 0;
    M m;
    SampleInfo info;
    while (r->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      n++;
      emit(describe(m));
    }
    return n;
  }
};

static std::unique_ptr<Endpoint> endpoint_of(const std::string& type)
{
  if (type == "go2_lowcmd") return std::unique_ptr<Endpoint>(new Typed<go::LowCmd_, go::LowCmd_PubSubType>());
  if (type == "go2_lowstate") return std::unique_ptr<Endpoint>(new Typed<go::LowState_, go::LowState_PubSubType>());
  if (type == "hg_lowstate") return std::unique_ptr<Endpoint>(new Typed<hg::LowState_, hg::LowState_PubSubType>());
  return nullptr;
}

// ---------------------------------------------------------------------------------------------
// Statuses, printed as they change.

static std::string guid_of(const InstanceHandle_t& h)
{
  return hex(h.value, 16);
}

struct WriterEvents : DataWriterListener
{
  std::atomic<int> matched{0};
  std::atomic<int> incompatible{0};
  void on_publication_matched(DataWriter*, const PublicationMatchedStatus& s) override
  {
    matched = s.current_count;
    Json("publication_matched").integer("current", s.current_count).integer("total", s.total_count)
        .str("reader", guid_of(s.last_subscription_handle)).print();
  }
  void on_offered_incompatible_qos(DataWriter*, const OfferedIncompatibleQosStatus& s) override
  {
    incompatible = static_cast<int>(s.total_count);
    Json("offered_incompatible_qos").integer("total", s.total_count).integer("policy", s.last_policy_id).print();
  }
};

struct ReaderEvents : DataReaderListener
{
  std::atomic<int> matched{0};
  std::atomic<int> incompatible{0};
  void on_subscription_matched(DataReader*, const SubscriptionMatchedStatus& s) override
  {
    matched = s.current_count;
    Json("subscription_matched").integer("current", s.current_count).integer("total", s.total_count)
        .str("writer", guid_of(s.last_publication_handle)).print();
  }
  void on_requested_incompatible_qos(DataReader*, const RequestedIncompatibleQosStatus& s) override
  {
    incompatible = static_cast<int>(s.total_count);
    Json("requested_incompatible_qos").integer("total", s.total_count).integer("policy", s.last_policy_id).print();
  }
};

// ---------------------------------------------------------------------------------------------

static std::atomic<bool> stdin_closed{false};

static void sleep_ms(int ms)
{
  std::this_thread::sleep_for(std::chrono::milliseconds(ms));
}

template <typename Qos>
static void set_qos(Qos& q, bool reliable, bool transient, int depth)
{
  q.reliability().kind = reliable ? RELIABLE_RELIABILITY_QOS : BEST_EFFORT_RELIABILITY_QOS;
  q.durability().kind = transient ? TRANSIENT_LOCAL_DURABILITY_QOS : VOLATILE_DURABILITY_QOS;
  q.history().kind = KEEP_LAST_HISTORY_QOS;
  q.history().depth = depth;
}

int main(int argc, char** argv)
{
  if (argc < 2) {
    std::fprintf(stderr, "usage: peer pub|sub|discover key=value...\n");
    return 2;
  }
  std::string scenario = argv[1];
  std::map<std::string, std::string> args;
  for (int i = 2; i < argc; i++) {
    std::string a = argv[i];
    size_t eq = a.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "not key=value: %s\n", a.c_str());
      return 2;
    }
    args[a.substr(0, eq)] = a.substr(eq + 1);
  }
  auto text = [&](const char* k, const char* d) { return args.count(k) ? args[k] : std::string(d); };
  auto number = [&](const char* k, int d) { return args.count(k) ? std::atoi(args[k].c_str()) : d; };
  std::string type = text("type", scenario == "pub" ? "go2_lowstate" : "go2_lowcmd");
  std::string topic_name = text("topic", type == "go2_lowcmd" ? "rt/lowcmd" : "rt/lowstate");
  bool reliable = text("reliability", "reliable") != "besteffort";
  bool transient = text("durability", "volatile") == "transient_local";
  int depth = number("depth", 1), count = number("count", 10), period = number("period_ms", 20);
  int wait_match = number("wait_match_ms", 10000), settle = number("settle_ms", 200);
  int linger = number("linger_ms", 2000), expect = number("expect", 0), seconds = number("seconds", 30);
  auto began = std::chrono::steady_clock::now();
  auto expired = [&] {
    return stdin_closed || std::chrono::steady_clock::now() - began > std::chrono::seconds(seconds);
  };
  std::thread([] {
    char b[256];
    while (read(0, b, sizeof b) > 0) {}
    stdin_closed = true;
  }).detach();

  DomainParticipantQos pqos = PARTICIPANT_QOS_DEFAULT;
  pqos.name("robowire-fastdds-peer");
  pqos.transport().use_builtin_transports = false;
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->maxMessageSize = 1472;
  pqos.transport().user_transports.push_back(udp);
  DomainParticipant* pp =
      DomainParticipantFactory::get_instance()->create_participant(number("domain", 0), pqos);
  if (pp == nullptr) {
    std::fprintf(stderr, "participant failed\n");
    return 1;
  }
  Json("ready").str("guid_prefix", hex(pp->guid().guidPrefix.value, 12)).print();

  WriterEvents wev;
  ReaderEvents rev;
  DataWriter* wr = nullptr;
  DataReader* rd = nullptr;
  std::unique_ptr<Endpoint> wtype, rtype;
  auto make_writer = [&](const std::string& t, const std::string& name) {
    wtype = endpoint_of(t);
    if (!wtype) return false;
    TypeSupport ts(wtype->type());
    ts.register_type(pp);
    Topic* topic = pp->create_topic(name, ts.get_type_name(), TOPIC_QOS_DEFAULT);
    Publisher* pub = pp->create_publisher(PUBLISHER_QOS_DEFAULT);
    DataWriterQos q = DATAWRITER_QOS_DEFAULT;
    set_qos(q, reliable, transient, depth);
    wr = topic && pub ? pub->create_datawriter(topic, q, &wev) : nullptr;
    return wr != nullptr;
  };
  auto make_reader = [&](const std::string& t, const std::string& name) {
    rtype = endpoint_of(t);
    if (!rtype) return false;
    TypeSupport ts(rtype->type());
    ts.register_type(pp);
    Topic* topic = pp->create_topic(name, ts.get_type_name(), TOPIC_QOS_DEFAULT);
    Subscriber* sub = pp->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
    DataReaderQos q = DATAREADER_QOS_DEFAULT;
    set_qos(q, reliable, transient, std::max(depth, 1));
    rd = topic && sub ? sub->create_datareader(topic, q, &rev) : nullptr;
    return rd != nullptr;
  };

  int written = 0, received = 0;
  bool ok = true;
  if (scenario == "pub") {
    ok = make_writer(type, topic_name);
    if (ok) {
      while (wait_match > 0 && wev.matched == 0 && !expired()) {
        if (std::chrono::steady_clock::now() - began > std::chrono::milliseconds(wait_match)) break;
        sleep_ms(5);
      }
      if (wev.matched > 0) sleep_ms(settle);
      uint32_t first = static_cast<uint32_t>(number("start", 0));
      for (int i = 0; (count == 0 || i < count) && !expired(); i++) {
        long long crc = wtype->write(wr, first + static_cast<uint32_t>(i));
        if (crc < 0) {
          Json("write_failed").integer("index", first + i).print();
        } else {
          written++;
          Json("written").integer("index", first + i).integer("crc", crc).print();
        }
        sleep_ms(period);
      }
      for (int t = 0; t < linger / 10 && !expired(); t++) sleep_ms(10);
    }
  } else if (scenario == "sub") {
    ok = make_reader(type, topic_name);
    while (ok && !expired() && (expect == 0 || received < expect)) {
      received += rtype->take(rd);
      sleep_ms(2);
    }
    for (int t = 0; ok && t < linger / 10 && !expired(); t++) sleep_ms(10);
  } else if (scenario == "discover") {
    ok = make_reader("go2_lowcmd", "rt/lowcmd") && make_writer("go2_lowstate", "rt/lowstate");
    while (ok && !expired() && !(wev.matched > 0 && rev.matched > 0)) sleep_ms(5);
    for (int t = 0; ok && t < linger / 10 && !expired(); t++) sleep_ms(10);
  } else {
    std::fprintf(stderr, "unknown scenario %s\n", scenario.c_str());
    return 2;
  }
  if (!ok) {
    std::fprintf(stderr, "creating the endpoints failed (type %s)\n", type.c_str());
    return 1;
  }
  Json("summary").integer("written", written).integer("received", received)
      .integer("publication_matched", wev.matched).integer("subscription_matched", rev.matched)
      .integer("offered_incompatible_qos", wev.incompatible)
      .integer("requested_incompatible_qos", rev.incompatible).print();
  pp->delete_contained_entities();
  DomainParticipantFactory::get_instance()->delete_participant(pp);
  return 0;
}
