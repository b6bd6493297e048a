#pragma once
// Private: a VTK reader's errors caught as one message for an InputError, with VTK's own
// printing to the terminal silenced while it reads (its pipeline and parsers print errors and
// warnings of their own that no observer on the reader sees). Not for concurrent readers: the
// silence is process-wide.
#include <string>

class vtkCallbackCommand;
class vtkObject;

namespace cranioplan::detail {

class VtkErrorCatcher {
 public:
  /// Observes `reader`'s error and warning events until destroyed.
  explicit VtkErrorCatcher(vtkObject* reader);
  ~VtkErrorCatcher();
  VtkErrorCatcher(const VtkErrorCatcher&) = delete;
  VtkErrorCatcher& operator=(const VtkErrorCatcher&) = delete;
  /// The first error or warning without the VTK source file and object it names, at most
  /// `max_chars` long; empty if none.
  std::string message(size_t max_chars = 200) const;

 private:
  std::string first_;
  vtkCallbackCommand* callback_;
  int verbosity_was_;     // the log's cutoff before (only its terminal output is in use)
  int display_mode_was_;  // the output window's
};

}  // namespace cranioplan::detail
