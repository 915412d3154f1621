// A small HDF5 writer and reader over the C API (HDF5 1.10, serial): datasets of doubles and
// integers with a shape, attributes, groups, and appendable time series. Each program writes its
// own file; nothing here is collective. Every write is followed by a flush, so a crash keeps
// everything written before it. Errors are fsi::Error naming the file and the object.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "error.hpp"

namespace fsi {

// Shapes are in C order, slowest index first: a grid field with i fastest has shape {ny, nx}.
// An empty shape means 1D of the data's length.
using H5Shape = std::vector<std::size_t>;

// "/step_000012": the group of one output step (six digits, wider when needed).
std::string h5_step_group(long step);

class H5File {
 public:
  enum class Mode {
    truncate,    // create, replacing any existing file
    read_write,  // open an existing file to add to it (a restart)
    read_only,
  };

  H5File(const std::filesystem::path& path, Mode mode);
  ~H5File();
  H5File(H5File&& other) noexcept;
  H5File& operator=(H5File&& other) noexcept;
  H5File(const H5File&) = delete;
  H5File& operator=(const H5File&) = delete;

  const std::filesystem::path& path() const { return m_path; }

  // Object names are HDF5 paths ("/step_000012/u" or "u", relative to the root). Writing creates
  // missing parent groups. Writing a dataset that exists replaces it (in place when the type and
  // shape agree, as a checkpoint rewritten each time does).
  void create_group(std::string_view name);
  bool exists(std::string_view name) const;
  // The names of a group's members (links), sorted; remove() unlinks one (a restart drops the
  // output steps beyond its step).
  std::vector<std::string> children(std::string_view group) const;
  void remove(std::string_view name);

  // Store `data` (row-major, product of `shape` values) as 64-bit floats or integers.
  void write(std::string_view name, std::span<const double> data, const H5Shape& shape = {});
  void write(std::string_view name, std::span<const int> data, const H5Shape& shape = {});
  void write(std::string_view name, std::span<const std::int64_t> data, const H5Shape& shape = {});

  // Store a window of a larger 2D row-major array without copying it, e.g. the interior of a
  // field with ghost layers: `data` has shape `full` = {ny_total, nx_total}; the stored dataset is
  // the block of shape `count` starting at `offset` = {j0, i0}.
  void write_window(std::string_view name, std::span<const double> data, const H5Shape& full,
                    const H5Shape& offset, const H5Shape& count);

  // Attributes on the file ("/"), a group or a dataset; setting one that exists replaces it.
  void set_attribute(std::string_view object, std::string_view key, double value);
  void set_attribute(std::string_view object, std::string_view key, std::int64_t value);
  void set_attribute(std::string_view object, std::string_view key, int value) {
    set_attribute(object, key, static_cast<std::int64_t>(value));
  }
  void set_attribute(std::string_view object, std::string_view key, std::string_view value);
  void set_attribute(std::string_view object, std::string_view key, const char* value) {
    set_attribute(object, key, std::string_view(value));
  }
  void set_attribute(std::string_view object, std::string_view key, std::span<const double> values);
  bool has_attribute(std::string_view object, std::string_view key) const;
  double attribute_number(std::string_view object, std::string_view key) const;
  std::string attribute_string(std::string_view object, std::string_view key) const;
  std::vector<double> attribute_numbers(std::string_view object, std::string_view key) const;

  // Appendable series: an extendible, chunked dataset that grows by one row per append. A series
  // of width 0 is 1D (one number per row: the output times); width w > 0 makes it 2D {rows, w}
  // (one probe row, one fiber's root load ...). Creating a series that exists with the same width
  // keeps its rows (a restart appends to them).
  void create_series(std::string_view name, std::size_t width);
  void append(std::string_view name, std::span<const double> row);
  void append(std::string_view name, double value) { append(name, std::span<const double>(&value, 1)); }
  // Drop rows beyond `rows` (a restart from an earlier step).
  void truncate_series(std::string_view name, std::size_t rows);

  // Reading back (checkpoints, tests): the dataset converted to the asked type, and its shape.
  H5Shape shape(std::string_view name) const;
  // The stored element type: "float64", "float32", "int32", "int64", "uint8" ... or "other".
  std::string type_name(std::string_view name) const;
  std::vector<double> read_doubles(std::string_view name) const;
  std::vector<int> read_ints(std::string_view name) const;
  std::vector<std::int64_t> read_int64s(std::string_view name) const;

  void flush();

 private:
  template <class T>
  void write_typed(std::string_view name, std::span<const T> data, const H5Shape& shape);
  template <class T>
  std::vector<T> read_typed(std::string_view name) const;
  void set_attribute_raw(std::string_view object, std::string_view key, std::int64_t type,
                         const H5Shape& shape, const void* data);
  [[noreturn]] void raise(const std::string& what, std::string_view object) const;
  void close() noexcept;

  std::filesystem::path m_path;
  std::int64_t m_id = -1;  // hid_t of the open file
  bool m_is_writable = false;
  // A write failed (disk full, I/O error): the file is not flushed or closed again, so that what
  // is on disk stays the file as of its last complete flush (every earlier step readable).
  mutable bool m_failed = false;
  // Before writing `bytes`: fails with "no space left on device" when the file system cannot
  // take them (and a margin for HDF5's own records), before anything of the write is done.
  void ensure_space(std::size_t bytes, std::string_view object) const;
};

}  // namespace fsi
