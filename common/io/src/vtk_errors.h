#pragma once
// Private to toolkit_io: turning VTK's error events and codes into one-line
// messages for IoError (instead of VTK printing them to stderr).
#include <vtkCommand.h>
#include <vtkErrorCode.h>

#include <cstring>
#include <string>

namespace toolkit::io::detail {

/// Collects the messages of ErrorEvents (instead of VTK printing them to stderr).
class ErrorCollector : public vtkCommand {
 public:
  static ErrorCollector* New() { return new ErrorCollector; }
  void Execute(vtkObject* /*caller*/, unsigned long event, void* call_data) override {
    if (event == vtkCommand::ErrorEvent && call_data != nullptr && message.empty())
      message = static_cast<const char*>(call_data);
  }
  std::string message;
};

/// vtkErrorCode::GetStringFromErrorCode lives in CommonMisc, which we do not link.
inline std::string error_code_text(unsigned long code) {
  switch (code) {
    case vtkErrorCode::FileNotFoundError: return "file not found";
    case vtkErrorCode::CannotOpenFileError: return "cannot open file";
    case vtkErrorCode::PrematureEndOfFileError: return "premature end of file";
    case vtkErrorCode::NoFileNameError: return "no file name";
    case vtkErrorCode::OutOfDiskSpaceError: return "out of disk space";
    default: break;
  }
  if (code < vtkErrorCode::FirstVTKErrorCode) return std::strerror(static_cast<int>(code));  // errno value
  return "VTK error code " + std::to_string(code);
}

/// The text of a VTK error message without its "ERROR: In FILE, line N" header
/// and "ClassName (0x...): " prefix; one line.
inline std::string vtk_message_text(const std::string& msg) {
  std::size_t pos = 0;
  while (pos < msg.size()) {
    std::size_t end = msg.find('\n', pos);
    if (end == std::string::npos) end = msg.size();
    std::string line = msg.substr(pos, end - pos);
    pos = end + 1;
    if (line.empty() || line.rfind("ERROR: In ", 0) == 0) continue;
    if (const auto sep = line.find("): "); sep != std::string::npos) line.erase(0, sep + 3);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) return line;
  }
  return {};
}

}  // namespace toolkit::io::detail
