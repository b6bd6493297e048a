#include "io/vtk_errors.h"

#include <gtest/gtest.h>
#include <vtkCommand.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkXMLPolyDataReader.h>

#include "support/test_files.h"

namespace cranioplan {
namespace {

// VTK's messages name its own source file and object; what is left says what went wrong.
TEST(VtkErrors, TheFirstMessageIsKeptWithoutVtksSourceAndObject) {
  vtkNew<vtkXMLPolyDataReader> reader;
  detail::VtkErrorCatcher catcher(reader);
  EXPECT_EQ(catcher.message(), "");
  std::string first =
      "ERROR: In ./IO/XML/vtkXMLReader.cxx, line 521\nvtkXMLPolyDataReader (0x5616aa): Error "
      "parsing input file.\n";
  reader->InvokeEvent(vtkCommand::ErrorEvent, first.data());
  std::string second = "a later message";
  reader->InvokeEvent(vtkCommand::WarningEvent, second.data());
  EXPECT_EQ(catcher.message(), "Error parsing input file.");
  EXPECT_EQ(catcher.message(5), "Error");
}

TEST(VtkErrors, AReaderFailsSilentlyAndTheTerminalIsGivenBack) {
  test::TempDir dir;
  test::write_bytes(dir.path("broken.vtp"), "<VTKFile type=\"PolyData\"><broken");
  const int before = vtkLogger::GetCurrentVerbosityCutoff();
  testing::internal::CaptureStderr();
  std::string message;
  {
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName(dir.path("broken.vtp").c_str());
    detail::VtkErrorCatcher catcher(reader);
    reader->Update();
    message = catcher.message();
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_FALSE(message.empty());
  EXPECT_EQ(message.find("vtkXMLReader.cxx"), std::string::npos) << message;
  EXPECT_EQ(vtkLogger::GetCurrentVerbosityCutoff(), before);
}

}  // namespace
}  // namespace cranioplan
