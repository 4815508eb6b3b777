// ReadResultStatus: the /timing attributes of a results file (written by ResultsWriter::Close).
#include "io/result_status.h"

#include <hdf5.h>

#include <filesystem>

#include "io/h5_handle.h"
#include <vector>

namespace surge {
namespace {

// Closes an HDF5 id on scope exit (negative ids are "none").
struct Id {
  hid_t id;
  herr_t (*close)(hid_t);
  ~Id() {
    if (id >= 0) close(id);
  }
};

bool ReadStringAttr(hid_t obj, const char* name, std::string& out) {
  if (H5Aexists(obj, name) <= 0) return false;
  Id attr{H5Aopen(obj, name, H5P_DEFAULT), H5Aclose};
  if (attr.id < 0) return false;
  Id type{H5Aget_type(attr.id), H5Tclose};
  if (type.id < 0 || H5Tget_class(type.id) != H5T_STRING) return false;
  // Exactly one string (the read writes every element) of a sane length.
  if (H5ElementCount(attr.id, false) != 1) return false;
  if (H5Tis_variable_str(type.id) > 0) {
    char* s = nullptr;
    Id mem{H5Tcopy(H5T_C_S1), H5Tclose};
    H5Tset_size(mem.id, H5T_VARIABLE);
    if (H5Aread(attr.id, mem.id, &s) < 0 || !s) return false;
    out = s;
    H5free_memory(s);
    return true;
  }
  // Fixed length, null padded (the writer's StringType).
  const size_t size = H5Tget_size(type.id);
  if (size == 0 || size > kH5MaxStringBytes) return false;
  std::vector<char> buf(size + 1, '\0');
  if (H5Aread(attr.id, type.id, buf.data()) < 0) return false;
  out.assign(buf.data());
  return true;
}

template <typename T>
bool ReadScalarAttr(hid_t obj, const char* name, hid_t mem_type, T& out) {
  if (H5Aexists(obj, name) <= 0) return false;
  Id attr{H5Aopen(obj, name, H5P_DEFAULT), H5Aclose};
  return attr.id >= 0 && H5ElementCount(attr.id, false) == 1 &&
         H5Aread(attr.id, mem_type, &out) >= 0;
}

}  // namespace

ResultStatus ReadResultStatus(const std::string& h5_path) {
  ResultStatus status;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(h5_path, ec)) return status;
  // No HDF5 error stack dumps on stderr for a broken file (as hdf5_writer.cpp does).
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  Id file{H5Fopen(h5_path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  if (file.id < 0) return status;
  status.readable = true;
  if (H5Lexists(file.id, "timing", H5P_DEFAULT) <= 0) return status;
  Id group{H5Gopen2(file.id, "timing", H5P_DEFAULT), H5Gclose};
  if (group.id < 0) return status;
  status.closed = ReadStringAttr(group.id, "exit_status", status.exit_status);
  ReadScalarAttr(group.id, "steps", H5T_NATIVE_INT64, status.steps);
  ReadScalarAttr(group.id, "wall_seconds", H5T_NATIVE_DOUBLE, status.wall_seconds);
  return status;
}

}  // namespace surge
