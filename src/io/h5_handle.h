// Owns an HDF5 id (hid_t) and closes it with the matching H5*close. Included only by the io
// library's .cpp files that already include <hdf5.h> (hdf5_writer.cpp, checkpoint.cpp).
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

}  // namespace surge
