#include "exit_deadline.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace balloon::server {

void exit_after(double timeout_s, const std::function<void(const std::string&)>& log) {
  std::thread([timeout_s, log] {
    std::this_thread::sleep_for(std::chrono::duration<double>(timeout_s));
    char seconds[32];
    std::snprintf(seconds, sizeof(seconds), "%g", timeout_s);
    if (log) log(std::string("drain timeout (") + seconds + " s) reached; exiting now (running jobs re-queue at the next start)");
    std::_Exit(1);
  }).detach();
}

}  // namespace balloon::server
