// HDF5 writer and reader over the C API. Every handle opened here is closed by a small RAII
// guard; HDF5's own error printing is switched off and its innermost message is carried in the
// fsi::Error instead.
#include "h5.hpp"

#include <sys/statvfs.h>

#include <cerrno>

#include <hdf5.h>

#include <algorithm>
#include <type_traits>

namespace fsi {

static_assert(std::is_same_v<hid_t, std::int64_t>, "HDF5 1.10 uses 64-bit hid_t");

namespace {

// Closes one HDF5 handle with the matching close function.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle(hid_t id, Closer closer) : m_id(id), m_closer(closer) {}
  ~Handle() {
    if (m_id >= 0) m_closer(m_id);
  }
  Handle(Handle&& other) noexcept : m_id(other.m_id), m_closer(other.m_closer) { other.m_id = -1; }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle& operator=(Handle&&) = delete;
  hid_t get() const { return m_id; }
  bool ok() const { return m_id >= 0; }

 private:
  hid_t m_id;
  Closer m_closer;
};

// The innermost HDF5 error description (the most specific one), or "" when there is none.
std::string hdf5_message() {
  std::string message;
  auto walk = [](unsigned n, const H5E_error2_t* e, void* out) -> herr_t {
    auto* text = static_cast<std::string*>(out);
    if (n == 0 && e->desc) *text = e->desc;
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, walk, &message);
  H5Eclear2(H5E_DEFAULT);
  return message;
}

void silence_hdf5() {
  static const bool done = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)done;
}

std::string object_name(std::string_view name) {
  std::string path;
  path.reserve(name.size() + 1);
  if (name.empty() || name.front() != '/') path.push_back('/');
  path.append(name);
  return path;
}

std::string shape_text(const H5Shape& shape) {
  std::string s = "{";
  for (std::size_t k = 0; k < shape.size(); ++k) {
    if (k) s += ", ";
    s += std::to_string(shape[k]);
  }
  return s + "}";
}

template <class T>
hid_t memory_type() {
  if constexpr (std::is_same_v<T, double>) return H5T_NATIVE_DOUBLE;
  if constexpr (std::is_same_v<T, int>) return H5T_NATIVE_INT;
  if constexpr (std::is_same_v<T, std::int64_t>) return H5T_NATIVE_INT64;
}

template <class T>
hid_t file_type() {
  if constexpr (std::is_same_v<T, double>) return H5T_IEEE_F64LE;
  if constexpr (std::is_same_v<T, int>) return H5T_STD_I32LE;
  if constexpr (std::is_same_v<T, std::int64_t>) return H5T_STD_I64LE;
}

std::vector<hsize_t> to_hsize(const H5Shape& shape) { return {shape.begin(), shape.end()}; }

std::size_t product(const H5Shape& shape) {
  std::size_t n = 1;
  for (auto s : shape) n *= s;
  return n;
}

H5Shape dataspace_shape(hid_t space) {
  int rank = H5Sget_simple_extent_ndims(space);
  if (rank <= 0) return {};
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  return {dims.begin(), dims.end()};
}

// Link-creation properties that create missing parent groups.
Handle intermediate_groups() {
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  return lcpl;
}

}  // namespace

std::string h5_step_group(long step) { return fmt::format("/step_{:06d}", step); }

H5File::H5File(const std::filesystem::path& path, Mode mode) : m_path(path) {
  silence_hdf5();
  m_is_writable = mode != Mode::read_only;
  // No file locks: ParaView or a script may read the file while the run writes it (each write
  // is flushed, so a reader sees the steps completed so far).
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_file_locking(fapl.get(), false, true);
  if (mode == Mode::truncate) {
    m_id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get());
    if (m_id < 0) raise("cannot create the file", "");
  } else {
    if (!std::filesystem::exists(path))
      throw Error(fmt::format("HDF5: cannot open {}: no such file", path.string()));
    m_id = H5Fopen(path.c_str(), m_is_writable ? H5F_ACC_RDWR : H5F_ACC_RDONLY, fapl.get());
    if (m_id < 0) raise("cannot open the file", "");
  }
}

H5File::~H5File() { close(); }

H5File::H5File(H5File&& other) noexcept
    : m_path(std::move(other.m_path)), m_id(other.m_id), m_is_writable(other.m_is_writable),
      m_failed(other.m_failed) {
  other.m_id = -1;
}

H5File& H5File::operator=(H5File&& other) noexcept {
  if (this != &other) {
    close();
    m_path = std::move(other.m_path);
    m_id = other.m_id;
    m_is_writable = other.m_is_writable;
    m_failed = other.m_failed;
    other.m_id = -1;
  }
  return *this;
}

void H5File::close() noexcept {
  if (m_id >= 0) {
    // After a failed write the handle is left open, unflushed: closing would write the metadata
    // of the half-written step over the file's last consistent state.
    if (m_failed && m_is_writable) {
      m_id = -1;
      return;
    }
    if (m_is_writable) H5Fflush(m_id, H5F_SCOPE_GLOBAL);
    H5Fclose(m_id);
    m_id = -1;
  }
}

namespace {

// Free bytes of the file system holding `file` (for a process that is not root); -1 unknown.
double free_bytes(const std::filesystem::path& file) {
  struct statvfs v;
  std::filesystem::path dir = file.parent_path();
  if (dir.empty()) dir = ".";
  if (::statvfs(dir.c_str(), &v) != 0) return -1;
  return static_cast<double>(v.f_bavail) * static_cast<double>(v.f_frsize);
}

// HDF5's own records beside the data of one write (object headers, B-tree nodes, the heap).
constexpr double kMetadataMargin = 64 * 1024;

}  // namespace

void H5File::ensure_space(std::size_t bytes, std::string_view object) const {
  const double have = free_bytes(m_path);
  if (have >= 0 && have < static_cast<double>(bytes) + kMetadataMargin) {
    m_failed = true;
    throw Error(fmt::format(
        "HDF5: no space left on device: writing '{}' ({} bytes) to {} needs about {:.0f} bytes, "
        "{:.0f} are free; the file holds every step written before this one",
        object_name(object), bytes, m_path.string(), bytes + kMetadataMargin, have));
  }
}

void H5File::raise(const std::string& what, std::string_view object) const {
  const int err = errno;
  std::string detail = hdf5_message();
  std::string where = object.empty() ? m_path.string() : fmt::format("'{}' in {}", object, m_path.string());
  if (m_is_writable) m_failed = true;
  const double have = m_is_writable ? free_bytes(m_path) : -1;
  if (m_is_writable && (err == ENOSPC || (have >= 0 && have < kMetadataMargin)))
    throw Error(fmt::format("HDF5: no space left on device: {} {}; the file holds every step "
                            "written before this one{}",
                            what, where, detail.empty() ? "" : " (" + detail + ")"));
  throw Error(fmt::format("HDF5: {} {}{}", what, where, detail.empty() ? "" : " (" + detail + ")"));
}

void H5File::flush() {
  if (m_failed) return;
  if (H5Fflush(m_id, H5F_SCOPE_GLOBAL) < 0) raise("cannot flush", "");
}

bool H5File::exists(std::string_view name) const {
  // Check each component so that a missing parent is "false", not an error.
  std::string path = object_name(name);
  if (path == "/") return true;
  std::size_t pos = 0;
  while (pos != std::string::npos) {
    pos = path.find('/', pos + 1);
    std::string prefix = path.substr(0, pos);
    if (H5Lexists(m_id, prefix.c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return false;
    }
  }
  return true;
}

std::vector<std::string> H5File::children(std::string_view group) const {
  std::vector<std::string> names;
  const std::string path = object_name(group);
  auto collect = [](hid_t, const char* name, const H5L_info_t*, void* out) -> herr_t {
    static_cast<std::vector<std::string>*>(out)->push_back(name);
    return 0;
  };
  if (H5Literate_by_name(m_id, path.c_str(), H5_INDEX_NAME, H5_ITER_INC, nullptr, collect, &names,
                          H5P_DEFAULT) < 0)
    raise("cannot list the members of", path);
  std::sort(names.begin(), names.end());
  return names;
}

void H5File::remove(std::string_view name) {
  const std::string path = object_name(name);
  if (H5Ldelete(m_id, path.c_str(), H5P_DEFAULT) < 0) raise("cannot remove", path);
  flush();
}

void H5File::create_group(std::string_view name) {
  std::string path = object_name(name);
  if (exists(path)) return;
  Handle lcpl = intermediate_groups();
  Handle group(H5Gcreate2(m_id, path.c_str(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  if (!group.ok()) raise("cannot create group", path);
  flush();
}

template <class T>
void H5File::write_typed(std::string_view name, std::span<const T> data, const H5Shape& shape_in) {
  std::string path = object_name(name);
  H5Shape shape = shape_in.empty() ? H5Shape{data.size()} : shape_in;
  if (product(shape) != data.size())
    throw Error(fmt::format("HDF5: dataset '{}' in {}: shape {} does not hold {} values", path,
                            m_path.string(), shape_text(shape), data.size()));
  ensure_space(data.size() * sizeof(T), path);
  std::vector<hsize_t> dims = to_hsize(shape);
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);

  if (exists(path)) {
    // Rewrite in place when the stored type class and shape agree; otherwise replace the link.
    Handle old(H5Dopen2(m_id, path.c_str(), H5P_DEFAULT), H5Dclose);
    bool is_same = false;
    if (old.ok()) {
      Handle old_space(H5Dget_space(old.get()), H5Sclose);
      Handle old_type(H5Dget_type(old.get()), H5Tclose);
      is_same = dataspace_shape(old_space.get()) == shape &&
                H5Tequal(old_type.get(), file_type<T>()) > 0 &&
                H5Sget_simple_extent_type(old_space.get()) == H5S_SIMPLE;
      Handle plist(H5Dget_create_plist(old.get()), H5Pclose);
      is_same = is_same && H5Pget_layout(plist.get()) != H5D_CHUNKED;
    }
    if (is_same) {
      if (H5Dwrite(old.get(), memory_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
        raise("cannot write dataset", path);
      flush();
      return;
    }
    if (H5Ldelete(m_id, path.c_str(), H5P_DEFAULT) < 0) raise("cannot replace dataset", path);
  }
  Handle lcpl = intermediate_groups();
  Handle set(H5Dcreate2(m_id, path.c_str(), file_type<T>(), space.get(), lcpl.get(), H5P_DEFAULT,
                        H5P_DEFAULT),
             H5Dclose);
  if (!set.ok()) raise("cannot create dataset", path);
  if (!data.empty() &&
      H5Dwrite(set.get(), memory_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
    raise("cannot write dataset", path);
  flush();
}

void H5File::write(std::string_view name, std::span<const double> data, const H5Shape& shape) {
  write_typed(name, data, shape);
}
void H5File::write(std::string_view name, std::span<const int> data, const H5Shape& shape) {
  write_typed(name, data, shape);
}
void H5File::write(std::string_view name, std::span<const std::int64_t> data, const H5Shape& shape) {
  write_typed(name, data, shape);
}

void H5File::write_window(std::string_view name, std::span<const double> data, const H5Shape& full,
                          const H5Shape& offset, const H5Shape& count) {
  std::string path = object_name(name);
  if (count.size() == 2) ensure_space(count[0] * count[1] * sizeof(double), path);
  if (full.size() != 2 || offset.size() != 2 || count.size() != 2)
    throw Error(fmt::format("HDF5: dataset '{}' in {}: write_window takes 2D shapes", path,
                            m_path.string()));
  if (product(full) != data.size() || offset[0] + count[0] > full[0] || offset[1] + count[1] > full[1])
    throw Error(fmt::format("HDF5: dataset '{}' in {}: window {} at {} does not fit array {} of {} values",
                            path, m_path.string(), shape_text(count), shape_text(offset),
                            shape_text(full), data.size()));
  if (exists(path) && H5Ldelete(m_id, path.c_str(), H5P_DEFAULT) < 0)
    raise("cannot replace dataset", path);
  std::vector<hsize_t> full_dims = to_hsize(full), start = to_hsize(offset), dims = to_hsize(count);
  Handle memory(H5Screate_simple(2, full_dims.data(), nullptr), H5Sclose);
  H5Sselect_hyperslab(memory.get(), H5S_SELECT_SET, start.data(), nullptr, dims.data(), nullptr);
  Handle space(H5Screate_simple(2, dims.data(), nullptr), H5Sclose);
  Handle lcpl = intermediate_groups();
  Handle set(H5Dcreate2(m_id, path.c_str(), H5T_IEEE_F64LE, space.get(), lcpl.get(), H5P_DEFAULT,
                        H5P_DEFAULT),
             H5Dclose);
  if (!set.ok()) raise("cannot create dataset", path);
  if (product(count) > 0 &&
      H5Dwrite(set.get(), H5T_NATIVE_DOUBLE, memory.get(), space.get(), H5P_DEFAULT, data.data()) < 0)
    raise("cannot write dataset", path);
  flush();
}

// ---- attributes ----

void H5File::set_attribute_raw(std::string_view object, std::string_view key, hid_t type,
                               const H5Shape& shape, const void* data) {
  std::string path = object_name(object);
  std::string k(key);
  std::string what = fmt::format("{}@{}", path, k);
  Handle obj(H5Oopen(m_id, path.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.ok()) raise("cannot open object for attribute", what);
  if (H5Aexists(obj.get(), k.c_str()) > 0 && H5Adelete(obj.get(), k.c_str()) < 0)
    raise("cannot replace attribute", what);
  std::vector<hsize_t> dims = to_hsize(shape);
  Handle space(shape.empty() ? H5Screate(H5S_SCALAR)
                             : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
               H5Sclose);
  Handle attr(H5Acreate2(obj.get(), k.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.ok()) raise("cannot create attribute", what);
  if (H5Awrite(attr.get(), type, data) < 0) raise("cannot write attribute", what);
  flush();
}

void H5File::set_attribute(std::string_view object, std::string_view key, double value) {
  set_attribute_raw(object, key, H5T_NATIVE_DOUBLE, {}, &value);
}

void H5File::set_attribute(std::string_view object, std::string_view key, std::int64_t value) {
  set_attribute_raw(object, key, H5T_NATIVE_INT64, {}, &value);
}

void H5File::set_attribute(std::string_view object, std::string_view key, std::span<const double> values) {
  set_attribute_raw(object, key, H5T_NATIVE_DOUBLE, {values.size()}, values.data());
}

// Strings are variable-length UTF-8, which h5py reads as str.
void H5File::set_attribute(std::string_view object, std::string_view key, std::string_view value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), H5T_VARIABLE);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  std::string text(value);
  const char* pointer = text.c_str();
  set_attribute_raw(object, key, type.get(), {}, &pointer);
}

bool H5File::has_attribute(std::string_view object, std::string_view key) const {
  std::string path = object_name(object);
  if (!exists(path)) return false;
  htri_t found = H5Aexists_by_name(m_id, path.c_str(), std::string(key).c_str(), H5P_DEFAULT);
  H5Eclear2(H5E_DEFAULT);
  return found > 0;
}

std::vector<double> H5File::attribute_numbers(std::string_view object, std::string_view key) const {
  std::string path = object_name(object);
  std::string what = fmt::format("{}@{}", path, key);
  Handle attr(H5Aopen_by_name(m_id, path.c_str(), std::string(key).c_str(), H5P_DEFAULT, H5P_DEFAULT),
              H5Aclose);
  if (!attr.ok()) raise("no attribute", what);
  Handle space(H5Aget_space(attr.get()), H5Sclose);
  hssize_t n = H5Sget_simple_extent_npoints(space.get());
  std::vector<double> values(static_cast<std::size_t>(std::max<hssize_t>(n, 0)));
  if (H5Aread(attr.get(), H5T_NATIVE_DOUBLE, values.data()) < 0) raise("cannot read attribute as numbers", what);
  return values;
}

double H5File::attribute_number(std::string_view object, std::string_view key) const {
  std::vector<double> values = attribute_numbers(object, key);
  if (values.size() != 1)
    throw Error(fmt::format("HDF5: attribute '{}@{}' in {} holds {} values, not one",
                            object_name(object), key, m_path.string(), values.size()));
  return values[0];
}

std::string H5File::attribute_string(std::string_view object, std::string_view key) const {
  std::string path = object_name(object);
  std::string what = fmt::format("{}@{}", path, key);
  Handle attr(H5Aopen_by_name(m_id, path.c_str(), std::string(key).c_str(), H5P_DEFAULT, H5P_DEFAULT),
              H5Aclose);
  if (!attr.ok()) raise("no attribute", what);
  Handle type(H5Aget_type(attr.get()), H5Tclose);
  if (H5Tget_class(type.get()) != H5T_STRING) raise("attribute is not a string", what);
  if (H5Tis_variable_str(type.get()) > 0) {
    char* pointer = nullptr;
    if (H5Aread(attr.get(), type.get(), &pointer) < 0) raise("cannot read attribute", what);
    std::string text = pointer ? pointer : "";
    H5free_memory(pointer);
    return text;
  }
  std::string text(H5Tget_size(type.get()), '\0');
  if (H5Aread(attr.get(), type.get(), text.data()) < 0) raise("cannot read attribute", what);
  text.resize(std::min(text.size(), text.find('\0')));
  return text;
}

// ---- appendable series ----

void H5File::create_series(std::string_view name, std::size_t width) {
  std::string path = object_name(name);
  H5Shape expected_tail = width == 0 ? H5Shape{} : H5Shape{width};
  if (exists(path)) {
    H5Shape s = shape(path);
    if (H5Shape(s.begin() + (s.empty() ? 0 : 1), s.end()) != expected_tail)
      throw Error(fmt::format("HDF5: series '{}' in {} exists with shape {}, not width {}", path,
                              m_path.string(), shape_text(s), width));
    return;
  }
  int rank = width == 0 ? 1 : 2;
  hsize_t dims[2] = {0, width}, max_dims[2] = {H5S_UNLIMITED, width};
  // About 8 KiB per chunk: appends stay cheap and small series stay small.
  hsize_t chunk[2] = {std::max<hsize_t>(1, 1024 / std::max<hsize_t>(width, 1)), std::max<hsize_t>(width, 1)};
  Handle space(H5Screate_simple(rank, dims, max_dims), H5Sclose);
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_chunk(dcpl.get(), rank, chunk);
  Handle lcpl = intermediate_groups();
  Handle set(H5Dcreate2(m_id, path.c_str(), H5T_IEEE_F64LE, space.get(), lcpl.get(), dcpl.get(),
                        H5P_DEFAULT),
             H5Dclose);
  if (!set.ok()) raise("cannot create series", path);
  flush();
}

void H5File::append(std::string_view name, std::span<const double> row) {
  std::string path = object_name(name);
  ensure_space(row.size() * sizeof(double), path);
  Handle set(H5Dopen2(m_id, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.ok()) raise("no series (create_series first)", path);
  Handle space(H5Dget_space(set.get()), H5Sclose);
  int rank = H5Sget_simple_extent_ndims(space.get());
  hsize_t dims[2] = {0, 1};
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  std::size_t width = rank == 1 ? 1 : dims[1];
  if (row.size() != width)
    throw Error(fmt::format("HDF5: series '{}' in {}: row of {} values, the series has width {}", path,
                            m_path.string(), row.size(), width));
  hsize_t grown[2] = {dims[0] + 1, dims[1]};
  if (H5Dset_extent(set.get(), grown) < 0) raise("cannot extend series", path);
  Handle file_space(H5Dget_space(set.get()), H5Sclose);
  hsize_t start[2] = {dims[0], 0}, count[2] = {1, width};
  H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr);
  Handle memory(H5Screate_simple(rank, count, nullptr), H5Sclose);
  if (H5Dwrite(set.get(), H5T_NATIVE_DOUBLE, memory.get(), file_space.get(), H5P_DEFAULT, row.data()) < 0)
    raise("cannot append to series", path);
  flush();
}

void H5File::truncate_series(std::string_view name, std::size_t rows) {
  std::string path = object_name(name);
  Handle set(H5Dopen2(m_id, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.ok()) raise("no series", path);
  Handle space(H5Dget_space(set.get()), H5Sclose);
  hsize_t dims[2] = {0, 1};
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  if (rows >= dims[0]) return;
  dims[0] = rows;
  if (H5Dset_extent(set.get(), dims) < 0) raise("cannot shrink series", path);
  flush();
}

// ---- reading ----

H5Shape H5File::shape(std::string_view name) const {
  std::string path = object_name(name);
  Handle set(H5Dopen2(m_id, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.ok()) raise("no dataset", path);
  Handle space(H5Dget_space(set.get()), H5Sclose);
  return dataspace_shape(space.get());
}

std::string H5File::type_name(std::string_view name) const {
  std::string path = object_name(name);
  Handle set(H5Dopen2(m_id, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.ok()) raise("no dataset", path);
  Handle type(H5Dget_type(set.get()), H5Tclose);
  std::size_t bits = 8 * H5Tget_size(type.get());
  switch (H5Tget_class(type.get())) {
    case H5T_FLOAT: return fmt::format("float{}", bits);
    case H5T_INTEGER:
      return fmt::format("{}int{}", H5Tget_sign(type.get()) == H5T_SGN_NONE ? "u" : "", bits);
    default: return "other";
  }
}

template <class T>
std::vector<T> H5File::read_typed(std::string_view name) const {
  std::string path = object_name(name);
  Handle set(H5Dopen2(m_id, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.ok()) raise("no dataset", path);
  Handle space(H5Dget_space(set.get()), H5Sclose);
  std::vector<T> values(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.get())));
  if (!values.empty() &&
      H5Dread(set.get(), memory_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
    raise("cannot read dataset", path);
  return values;
}

std::vector<double> H5File::read_doubles(std::string_view name) const { return read_typed<double>(name); }
std::vector<int> H5File::read_ints(std::string_view name) const { return read_typed<int>(name); }
std::vector<std::int64_t> H5File::read_int64s(std::string_view name) const {
  return read_typed<std::int64_t>(name);
}

}  // namespace fsi
