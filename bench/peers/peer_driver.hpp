// The command line shared by the peer drivers (bench/peers/*.cpp): `PEER INPUT OUTPUT.stl`.
// Reads the cloud with g2s::read_points, times the peer's reconstruction (everything between
// reading and writing: normal estimation and spacing included), writes the mesh with
// g2s::write_mesh so `g2s stats` checks it like a g2s mesh, and prints one JSON line on stdout:
// {"method", "points", "triangles", "seconds"} (seconds = the reconstruction alone). Exit codes
// are g2s's (README.md): 2 bad command line, 3 bad input, 4 write failed, 1 anything else.
#pragma once

#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/types.hpp"

namespace g2s::peers {

// Runs `reconstruct(cloud) -> IndexedMesh` as the peer `method`. reconstruct may move the
// cloud's coordinates into the mesh it returns.
template <class Reconstruct>
int run_peer(int argc, char** argv, const char* method, Reconstruct&& reconstruct) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s INPUT OUTPUT.stl\n", argv[0]);
    return static_cast<int>(Exit::usage);
  }
  try {
    install_interrupt_cleanup();
    PointCloud cloud = read_points(argv[1]);
    if (cloud.size() < 3)
      throw Error(Exit::bad_input, std::string(argv[1]) + ": fewer than 3 points");
    const std::size_t points = cloud.size();
    const auto t0 = std::chrono::steady_clock::now();
    const IndexedMesh mesh = reconstruct(cloud);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::filesystem::path output = argv[2];
    write_mesh(output, mesh.xyz, mesh.triangles, mesh_format_for(output, false));
    std::printf("{\"method\":\"%s\",\"points\":%zu,\"triangles\":%zu,\"seconds\":%.3f}\n", method,
                points, mesh.triangles.size(), seconds);
    return 0;
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: %s\n", method, e.what());
    return static_cast<int>(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", method, e.what());
    return static_cast<int>(Exit::failure);
  }
}

}  // namespace g2s::peers
