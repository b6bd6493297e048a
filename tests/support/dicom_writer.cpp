#include "support/dicom_writer.h"

#include <cstdint>
#include <cstdio>
#include <sstream>

#include "support/test_files.h"

namespace cranioplan::test {
namespace {

void put16(std::string& s, uint16_t v) { s.append(reinterpret_cast<const char*>(&v), 2); }
void put32(std::string& s, uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }

void element(std::string& s, uint16_t group, uint16_t elem, const char* vr, std::string value) {
  if (value.size() % 2) value.push_back(vr[0] == 'U' && vr[1] == 'I' ? '\0' : ' ');
  put16(s, group);
  put16(s, elem);
  s.append(vr, 2);
  const std::string v(vr, 2);
  if (v == "OB" || v == "OW" || v == "SQ" || v == "UN" || v == "UT") {
    put16(s, 0);
    put32(s, static_cast<uint32_t>(value.size()));
  } else {
    put16(s, static_cast<uint16_t>(value.size()));
  }
  s += value;
}

std::string us(uint16_t v) { return std::string(reinterpret_cast<const char*>(&v), 2); }

std::string ds(double a) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", a);
  return buf;
}

}  // namespace

void write_dicom_series(const Volume& v, const std::string& folder) {
  const Eigen::Vector3d sp = v.spacing();
  for (int k = 0; k < v.dims[2]; ++k) {
    std::string meta;
    element(meta, 0x0002, 0x0001, "OB", std::string("\0\1", 2));
    element(meta, 0x0002, 0x0002, "UI", "1.2.840.10008.5.1.4.1.1.2");
    element(meta, 0x0002, 0x0003, "UI", "1.2.3.4.5." + std::to_string(k + 1));
    element(meta, 0x0002, 0x0010, "UI", "1.2.840.10008.1.2.1");
    std::string file(128, '\0');
    file += "DICM";
    std::string group_length;
    put32(group_length, static_cast<uint32_t>(meta.size()));
    element(file, 0x0002, 0x0000, "UL", group_length);
    file += meta;
    const Eigen::Vector3d ipp = v.world(Eigen::Vector3d(0, 0, k));
    element(file, 0x0008, 0x0060, "CS", "CT");
    element(file, 0x0018, 0x0050, "DS", ds(sp.z()));
    element(file, 0x0020, 0x000D, "UI", "1.2.3.4");
    element(file, 0x0020, 0x000E, "UI", "1.2.3.4.1");
    element(file, 0x0020, 0x0013, "IS", std::to_string(k + 1));
    element(file, 0x0020, 0x0032, "DS", ds(ipp.x()) + "\\" + ds(ipp.y()) + "\\" + ds(ipp.z()));
    element(file, 0x0020, 0x0037, "DS", "1\\0\\0\\0\\1\\0");
    element(file, 0x0028, 0x0002, "US", us(1));
    element(file, 0x0028, 0x0004, "CS", "MONOCHROME2");
    element(file, 0x0028, 0x0010, "US", us(static_cast<uint16_t>(v.dims[1])));
    element(file, 0x0028, 0x0011, "US", us(static_cast<uint16_t>(v.dims[0])));
    element(file, 0x0028, 0x0030, "DS", ds(sp.y()) + "\\" + ds(sp.x()));
    element(file, 0x0028, 0x0100, "US", us(16));
    element(file, 0x0028, 0x0101, "US", us(16));
    element(file, 0x0028, 0x0102, "US", us(15));
    element(file, 0x0028, 0x0103, "US", us(0));
    element(file, 0x0028, 0x1052, "DS", "-1024");
    element(file, 0x0028, 0x1053, "DS", "1");
    std::string pixels;
    for (int j = 0; j < v.dims[1]; ++j)
      for (int i = 0; i < v.dims[0]; ++i)
        put16(pixels, static_cast<uint16_t>(v.at(i, j, k) + 1024));
    element(file, 0x7FE0, 0x0010, "OW", pixels);
    std::ostringstream name;
    name << folder << "/slice" << (1000 + k) << ".dcm";
    write_bytes(name.str(), file);
  }
}

}  // namespace cranioplan::test
