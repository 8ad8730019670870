// libFuzzer target: the tile store reader (what `g2s grow`, `g2s stitch` and `g2s tile-info` open),
// on any bytes: opening validates the header and table, loading a tile or its border checks the
// frames it reads. The input goes through a memfd, since a store is opened (and mapped) by path.
#include <sys/mman.h>
#include <unistd.h>

#include <string>

#include "fuzz_input.hpp"
#include "g2s/tile_store.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const int fd = memfd_create("fuzz-store", MFD_CLOEXEC);
  if (fd < 0) std::abort();
  for (std::size_t done = 0; done < size;) {
    const ssize_t n = write(fd, data + done, size - done);
    if (n <= 0) std::abort();
    done += static_cast<std::size_t>(n);
  }
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  g2s::fuzz::expect_clean_refusal([&] {
    const g2s::TileStore store(path);
    for (std::size_t t = 0; t < store.tiles().size(); ++t) {
      store.load_border(t, store.tiles()[t].spacing * 2);
      store.load(t);
    }
  });
  close(fd);
  return 0;
}
