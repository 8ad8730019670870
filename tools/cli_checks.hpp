// Checks shared by the subcommands before any work starts: an output must not be one of the
// inputs, an output's extension must name a format g2s writes, and option values must be finite
// and in range. Each failure is one short line saying what is valid (exit 2, README "Exit
// codes").
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <vector>

#include "g2s/io.hpp"

namespace g2s::cli {

// Fewer points in a tile give tiles too small to mesh (a tile needs its neighbours' points
// within a few spacings) and runs hundreds of times slower.
inline constexpr long long kFewestTilePoints = 500;
inline constexpr long long kMostThreads = 4096;

// Throws Error(usage) when `output` is the same file as one of `inputs`, however either is
// spelled (another relative path, a symbolic link, a hard link). Two paths that do not exist yet
// are the same when they name the same place (a --keep-store and the -o of one run). `what` names
// the output in the message ("-o", "the store").
void refuse_same_file(std::initializer_list<std::filesystem::path> inputs,
                      const std::filesystem::path& output, const std::string& what);

// The mesh format for `output` from its extension: .stl (binary, or ASCII with `ascii`) or
// .ply (binary); anything else, or --ascii with .ply, throws Error(usage).
MeshFormat checked_mesh_format(const std::filesystem::path& output, bool ascii);

// Throws Error(usage) unless `output` ends in `extension` (".png", ".ply"; any case).
void require_extension(const std::filesystem::path& output, const std::string& extension,
                       const std::string& what);

// Validators with one-line messages: a finite number in [lo, hi]; a whole number in [lo, hi].
CLI::Validator finite_range(double lo, double hi);
CLI::Validator count_range(long long lo, long long hi);
// Any whole number from 0 to 2^64 - 1, written as such: "-1" is refused, not taken as 2^64 - 1.
CLI::Validator unsigned_number();
// A byte size such as 512M or 4G (K, M, G, T, powers of 1024; "MB", "MiB" read as "M"), at least
// 1 MiB; written back as the number of bytes.
CLI::Validator byte_size();

// Radius steps: each finite and positive, strictly increasing; throws Error(usage) otherwise.
void check_radius_steps(const std::vector<double>& steps);

// CLI11's error messages replaced by one line that says what is valid.
std::string failure_message(const CLI::App* app, const CLI::Error& error);

}  // namespace g2s::cli
