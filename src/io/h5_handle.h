// Owns an HDF5 id (hid_t) and closes it with the matching H5*close, and the checks the readers
// make before reading. Included only by the io library's .cpp files that already include
// <hdf5.h> (hdf5_writer.cpp, checkpoint.cpp, result_status.cpp).
#pragma once
#include <hdf5.h>

namespace surge {

class H5Handle {
 public:
  H5Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~H5Handle() {
    if (id_ >= 0) close_(id_);
  }
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// --- checks the readers make before reading (a corrupt or hostile file must give an IoError,
// never an overflow or a huge allocation; found by tests/fuzz/fuzz_io) ---

// Number of elements of an attribute's (dataset = false) or dataset's dataspace; -1 on error.
// A scalar read (one value, one string) needs exactly 1: H5Aread/H5Dread write every element.
inline hssize_t H5ElementCount(hid_t obj, bool dataset) {
  const hid_t space = dataset ? H5Dget_space(obj) : H5Aget_space(obj);
  if (space < 0) return -1;
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  H5Sclose(space);
  return n;
}

// Longest fixed-length string a reader accepts [bytes] (scene texts are kilobytes): a corrupt
// type size must not become a multi-gigabyte allocation.
constexpr size_t kH5MaxStringBytes = size_t(64) << 20;

// True when dataset `ds` stores at least `elements` elements of its own type in the file
// (H5Dget_storage_size), i.e. its dimensions are not larger than the data the file holds for it,
// so that sizing a buffer by them cannot ask for more memory than the file justifies. Filtered
// (compressed) datasets are not checked: Surge writes none, a repacked file may have them.
inline bool H5StorageCovers(hid_t ds, hsize_t elements) {
  if (elements == 0) return true;
  const hid_t dcpl = H5Dget_create_plist(ds);
  if (dcpl < 0) return false;
  const int filters = H5Pget_nfilters(dcpl);
  H5Pclose(dcpl);
  if (filters != 0) return filters > 0;
  const hid_t type = H5Dget_type(ds);
  if (type < 0) return false;
  const size_t bytes = H5Tget_size(type);
  H5Tclose(type);
  return bytes > 0 && elements <= H5Dget_storage_size(ds) / bytes;
}

}  // namespace surge
