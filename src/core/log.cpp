// Logging facade over spdlog (stderr, so stdout stays for summaries).
#include "core/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

namespace surge {
namespace {

spdlog::logger& Logger() {
  static std::shared_ptr<spdlog::logger> logger = [] {
    auto l = spdlog::stderr_color_mt("surge");
    l->set_pattern("[%H:%M:%S] %^%l%$ %v");
    return l;
  }();
  return *logger;
}

}  // namespace

void SetLogLevel(LogLevel level) {
  static constexpr spdlog::level::level_enum kMap[] = {spdlog::level::debug, spdlog::level::info,
                                                       spdlog::level::warn, spdlog::level::err};
  Logger().set_level(kMap[static_cast<int>(level)]);
}

void Log(LogLevel level, const std::string& message) {
  switch (level) {
    case LogLevel::kDebug: Logger().debug(message); break;
    case LogLevel::kInfo: Logger().info(message); break;
    case LogLevel::kWarn: Logger().warn(message); break;
    case LogLevel::kError: Logger().error(message); break;
  }
}

}  // namespace surge
