// occull — the limits on input made by others.
//
// Every reader of a file or string from outside checks the size it is about
// to allocate against one of these caps first, so no length field in a file
// drives an allocation unchecked, and a file past a cap is an InputError
// (exit 2) that names the file, its value and the limit — never an
// out-of-memory kill. The caps sit far above any real input (the largest
// OpenArena map is ~10 MB; a 1M-object scene fits) and far below what would
// exhaust a 16 GiB machine.
//
// What is not capped here is bounded by a capped size: a BSP lump's records
// lie inside its map's bytes, a path file's keys inside its bytes, a
// patch's tessellated triangles grow linearly with its control points.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace occull::limits {

/// A Quake 3 map: a .bsp file, or a map's entry inside a .pk3 (its
/// uncompressed size, as read; the size the archive claims is not trusted).
inline constexpr std::uint64_t map_bytes = std::uint64_t(256) << 20;
/// A .pk3 archive (zip) itself: minizip reads only its directory and entries.
inline constexpr std::uint64_t archive_bytes = std::uint64_t(4) << 30;
/// A model file read through assimp (file:MODEL), before assimp allocates.
inline constexpr std::uint64_t model_bytes = std::uint64_t(512) << 20;
/// Importing a model (file:MODEL) runs assimp in a child process, so that a
/// reader that hangs, crashes or allocates without bound on a damaged file
/// ends that child with an InputError, not the caller's process. The child
/// may use this much CPU time, seconds (then SIGXCPU)...
inline constexpr unsigned model_import_cpu_seconds = 120;
/// ...this much wall-clock time, seconds (then the caller kills it)...
inline constexpr double model_import_wall_seconds = 300.0;
/// ...and this much address space beyond what it inherits, bytes (then
/// allocations fail: std::bad_alloc).
inline constexpr std::uint64_t model_import_bytes = std::uint64_t(8) << 30;
/// A text file: a recorded path (.path) or a hardware profile (JSON).
inline constexpr std::uint64_t text_file_bytes = std::uint64_t(16) << 20;
/// A viewport's or render target's side, pixels (GL_MAX_RENDERBUFFER_SIZE
/// of common drivers).
inline constexpr int viewport_side = 16384;
/// A scene spec ("city:blocks=40,...") or an algorithm spec, in characters.
inline constexpr std::size_t spec_chars = 4096;
/// Objects in one scene (Scene::add_object).
inline constexpr std::size_t objects = std::size_t(1) << 24;
/// Triangles stored in one scene's meshes, each mesh counted once
/// (instances share their mesh's triangles).
inline constexpr std::uint64_t mesh_triangles = std::uint64_t(1) << 26;

/// The whole of file `path` as bytes, refusing a file larger than `limit`
/// bytes before reading it. `what` names the kind of file and its cap in
/// the message (e.g. "a map (occull::limits::map_bytes)"). Throws
/// InputError when the file cannot be opened or read, or is larger than
/// `limit`: "PATH: N bytes is past the limit of L bytes for WHAT".
[[nodiscard]] std::string read_file(const std::string& path, std::uint64_t limit, std::string_view what);

/// Throws InputError "WHAT WxH: each side must be in [1, viewport_side]
/// pixels" unless both sides are in that range.
void check_viewport(int width, int height, std::string_view what);

/// Throws InputError when file `path` is larger than `limit` bytes (naming
/// the file, its size, the limit and `what` it is); does nothing when it is
/// not larger or cannot be inspected (the reader then reports that).
void check_file_size(const std::string& path, std::uint64_t limit, std::string_view what);

}  // namespace occull::limits
