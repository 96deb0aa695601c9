#include "strata/core/io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <string>
#include <system_error>

#include "strata/core/common/error.hpp"

namespace strata {
namespace {

std::filesystem::path temporary_path_for(const std::filesystem::path& path) {
  static std::atomic<unsigned long> counter{0};
  std::string name = ".";
  name += path.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  name += '-';
  name += std::to_string(counter++);
  return path.parent_path() / name;
}

/// Pushes the file's data to the disk, so a crash right after the rename cannot leave an empty
/// file.
void sync_file(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write) {
  if (path.empty()) throw InputError("cannot write a file with an empty path");
  const std::filesystem::path temporary = temporary_path_for(path);
  auto remove_temporary = [&] {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
  };
  try {
    {
      std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
      if (!out)
        throw InputError("cannot write '" + path.string() + "': cannot create a file in '" +
                         path.parent_path().string() + "'");
      write(out);
      out.flush();
      if (!out) throw InputError("cannot write '" + path.string() + "': write error (disk full?)");
      out.close();
      if (out.fail()) throw InputError("cannot write '" + path.string() + "': close failed");
    }
    sync_file(temporary);
    std::error_code error;
    std::filesystem::rename(temporary, path, error);
    if (error) throw InputError("cannot write '" + path.string() + "': " + error.message());
  } catch (...) {
    remove_temporary();
    throw;
  }
}

}  // namespace strata
