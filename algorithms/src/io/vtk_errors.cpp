#include "vtk_errors.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkLogger.h>
#include <vtkObject.h>
#include <vtkOutputWindow.h>

namespace cranioplan::detail {

VtkErrorCatcher::VtkErrorCatcher(vtkObject* reader)
    : callback_(vtkCallbackCommand::New()),
      verbosity_was_(vtkLogger::GetCurrentVerbosityCutoff()),
      display_mode_was_(vtkOutputWindow::GetInstance()->GetDisplayMode()) {
  callback_->SetClientData(&first_);
  callback_->SetCallback([](vtkObject*, unsigned long, void* client, void* call) {
    auto* first = static_cast<std::string*>(client);
    if (first->empty() && call) *first = static_cast<const char*>(call);
  });
  reader->AddObserver(vtkCommand::ErrorEvent, callback_);
  reader->AddObserver(vtkCommand::WarningEvent, callback_);
  // Errors of the pipeline's other objects (its executive, an XML or DICOM parser) reach no
  // observer of ours: VTK logs them to the terminal and its output window. Neither, meanwhile.
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  vtkOutputWindow::GetInstance()->SetDisplayModeToNever();
}

VtkErrorCatcher::~VtkErrorCatcher() {
  vtkOutputWindow::GetInstance()->SetDisplayMode(display_mode_was_);
  vtkLogger::SetStderrVerbosity(static_cast<vtkLogger::Verbosity>(verbosity_was_));
  callback_->Delete();
}

std::string VtkErrorCatcher::message(size_t max_chars) const {
  std::string m = first_;
  // "ERROR: In ./IO/XML/vtkXMLReader.cxx, line 521\nvtkXMLPolyDataReader (0x5616...): Error
  // parsing input file." says to a user no more than its last part.
  if (m.rfind("ERROR: In ", 0) == 0 || m.rfind("Warning: In ", 0) == 0) {
    const size_t eol = m.find('\n');
    m = eol == std::string::npos ? std::string() : m.substr(eol + 1);
  }
  const size_t object = m.find(" (0x");
  const size_t colon = m.find("): ");
  if (object != std::string::npos && colon != std::string::npos && object < colon &&
      m.find(' ') == object)
    m = m.substr(colon + 3);
  while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.pop_back();
  return m.substr(0, max_chars);
}

}  // namespace cranioplan::detail
