// SceneError: the one exception type for bad user input (STYLE H.7). Thrown only by the scene
// parser and builder; what() reads "file:line:column: key.path: message".
#pragma once
#include <stdexcept>
#include <string>

namespace surge {

class SceneError : public std::runtime_error {
 public:
  // `file` is the scene path, "<string>", or "--set key=value" for command-line overrides.
  // `line` and `column` are 1-based; 0 means "no position" (e.g. an unreadable file).
  SceneError(std::string file, int line, int column, std::string key_path, std::string message)
      : std::runtime_error(Format(file, line, column, key_path, message)),
        file_(std::move(file)),
        line_(line),
        column_(column),
        key_path_(std::move(key_path)),
        message_(std::move(message)) {}

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }
  const std::string& key_path() const { return key_path_; }  // e.g. "bodies[0].velocity"
  const std::string& message() const { return message_; }

 private:
  static std::string Format(const std::string& file, int line, int column,
                            const std::string& key_path, const std::string& message) {
    // Built with append(): GCC 12 warns falsely (-Wrestrict, PR 105329) on chained operator+.
    std::string s = file;
    if (line > 0) {
      s.append(":").append(std::to_string(line)).append(":").append(std::to_string(column));
    }
    s.append(": ");
    if (!key_path.empty()) s.append(key_path).append(": ");
    return s.append(message);
  }

  std::string file_;
  int line_;
  int column_;
  std::string key_path_;
  std::string message_;
};

}  // namespace surge
