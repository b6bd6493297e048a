// libFuzzer harness for one reader, chosen at compile time by CRANIOPLAN_FUZZ_READER. The
// input is written to a file of the reader's kind and read as the program reads it; a reader
// may refuse it only with cranioplan::Error (a message naming the file). Any other exception,
// a crash, a hang, a leak or undefined behaviour is a finding (AddressSanitizer and
// UndefinedBehaviorSanitizer are on).
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "cranioplan/algorithms/io/read_mesh.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/marker_files.h"
#include "cranioplan/sessions/plan_files.h"
#include "cranioplan/sessions/session.h"

namespace {

namespace fs = std::filesystem;
using namespace cranioplan;

// The process's own folder for the files it reads, removed when it exits (a replay runs once
// per test; none is left behind in the system's temporary folder).
const std::string& work_dir() {
  struct Dir {
    std::string path;
    Dir() {
      const fs::path p =
          fs::temp_directory_path() / ("cranioplan-fuzz-" + std::to_string(getpid()));
      fs::create_directories(p);
      path = p.string();
    }
    ~Dir() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  };
  static const Dir dir;
  return dir.path;
}

void write(const std::string& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// A DICOM input is a folder of slices: the input split at each separator into files.
constexpr std::string_view kSliceSeparator = "\n--cranioplan-slice--\n";

std::string dicom_folder(std::string_view data) {
  const std::string dir = work_dir() + "/series";
  fs::remove_all(dir);
  fs::create_directories(dir);
  int n = 0;
  while (n < 8) {
    const size_t at = data.find(kSliceSeparator);
    write(dir + "/s" + std::to_string(n++) + ".dcm", data.substr(0, at));
    if (at == std::string_view::npos) break;
    data.remove_prefix(at + kSliceSeparator.size());
  }
  return dir;
}

void read(std::string_view data) {
  const std::string reader = CRANIOPLAN_FUZZ_READER;
  const std::string base = work_dir() + "/input";
  if (reader == "stl" || reader == "ply" || reader == "obj" || reader == "off" || reader == "vtk" ||
      reader == "vtp") {
    write(base + "." + reader, data);
    read_mesh(base + "." + reader);
  } else if (reader == "nrrd" || reader == "nii" || reader == "inv3") {
    write(base + "." + reader, data);
    read_volume(base + "." + reader);
  } else if (reader == "dicom") {
    read_volume(dicom_folder(data));
  } else if (reader == "session") {
    write(base + ".json", data);
    read_session_document(base + ".json");
  } else if (reader == "landmarks") {
    // The same bytes as Cranioplan's JSON and as 3D Slicer's markups.
    write(base + ".json", data);
    write(base + ".mrk.json", data);
    try {
      read_landmarks_file(base + ".json");
    } catch (const cranioplan::Error&) {
    }
    read_landmarks_file(base + ".mrk.json");
  } else if (reader == "markers") {
    // Markers come as JSON (Cranioplan's, and the same bytes as Slicer's markups) or CSV: the
    // first byte chooses.
    const bool json = !data.empty() && data[0] == '{';
    const std::string path = base + (json ? ".json" : ".csv");
    write(path, data);
    if (json) {
      write(base + ".mrk.json", data);
      try {
        read_markers_file(base + ".mrk.json");
      } catch (const cranioplan::Error&) {
      }
    }
    read_markers_file(path);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* bytes, size_t size) {
  try {
    read(std::string_view(reinterpret_cast<const char*>(bytes), size));
  } catch (const cranioplan::Error&) {
    // A refusal with a message: what a bad file should get.
  }
  return 0;
}
