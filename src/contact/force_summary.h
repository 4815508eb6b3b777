// Peak and impulse of the per-step structure forces (issue #5): what a user asks of a force
// series first. Fed one ContactReport per step; kept by the results writer, which stores the
// result as attributes of /forces (docs/results-format.md). Plain C++, header-only.
#pragma once
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "contact/contact_report.h"
#include "core/check.h"
#include "core/math.h"

namespace surge {

// Running extremes and integral of one force series (a structure or one of its faces).
struct ForcePeak {
  Real peak_force = 0;  // largest |F| over the samples [N] (2-D: per metre of thickness)
  // Time of the first sample that reached peak_force [s]; NaN while no sample had a non-NaN |F|.
  Real peak_time = std::numeric_limits<Real>::quiet_NaN();
  Vec3 force_at_peak = Vec3::Zero();  // F at peak_time [N]
  Vec3 impulse = Vec3::Zero();        // sum over samples of F dt [N s]
  Real peak_contact_area = 0;         // largest contact area [m^2]
};

struct StructurePeak : ForcePeak {
  Real peak_wetted_height = 0;   // largest wetted height [m]
  std::vector<ForcePeak> faces;  // as ForceChannel::faces
};

class ForceSummary {
 public:
  explicit ForceSummary(const std::vector<ForceChannel>& channels) : channels_(channels) {
    structures_.resize(channels_.size());
    for (size_t s = 0; s < channels_.size(); ++s)
      structures_[s].faces.resize(channels_[s].faces.size());
  }

  // One step: `report` holds the forces of the step of length dt [s] stamped `time` [s] (the
  // writer passes the end of the step). Impulse by the rectangle rule, I += F dt. A sample whose
  // |F| is NaN never becomes the peak (its impulse does become NaN).
  // Pre: report has one entry per channel, each with one face entry per channel face.
  void Add(Real time, Real dt, const ContactReport& report) {
    SURGE_CHECK(report.structures.size() == channels_.size(),
                "ContactReport has " + std::to_string(report.structures.size()) +
                    " structures, the force channels " + std::to_string(channels_.size()));
    for (size_t s = 0; s < channels_.size(); ++s) {  // all checks before any change
      const size_t faces = report.structures[s].faces.size();
      SURGE_CHECK(faces == channels_[s].faces.size(),
                  "structure '" + channels_[s].name + "' reports " + std::to_string(faces) +
                      " faces, its channel has " + std::to_string(channels_[s].faces.size()));
    }
    for (size_t s = 0; s < channels_.size(); ++s) {
      const ObstacleForce& in = report.structures[s];
      StructurePeak& out = structures_[s];
      Accumulate(time, dt, in.force, in.contact_area, out);
      if (in.wetted_height > out.peak_wetted_height) out.peak_wetted_height = in.wetted_height;
      for (size_t f = 0; f < in.faces.size(); ++f)
        Accumulate(time, dt, in.faces[f].force, in.faces[f].contact_area, out.faces[f]);
    }
    ++samples_;
  }

  const std::vector<ForceChannel>& channels() const { return channels_; }
  size_t size() const { return structures_.size(); }
  // Pre: s < size().
  const StructurePeak& structure(size_t s) const { return structures_.at(s); }
  // Pre: s < size(), f < channels()[s].faces.size().
  const ForcePeak& face(size_t s, size_t f) const { return structures_.at(s).faces.at(f); }
  // Index of the structure called `name`, or -1.
  int Find(const std::string& name) const {
    for (size_t s = 0; s < channels_.size(); ++s)
      if (channels_[s].name == name) return int(s);
    return -1;
  }
  int64_t samples() const { return samples_; }

  // Continues from a summary saved in a checkpoint (io/checkpoint.h): every structure's running
  // peaks and impulses and the number of samples so far, as structure() and samples() gave them.
  // Pre: `peaks` has one entry per channel with one face entry per channel face.
  void Restore(const std::vector<StructurePeak>& peaks, int64_t samples) {
    SURGE_CHECK(peaks.size() == channels_.size(),
                "checkpoint has " + std::to_string(peaks.size()) + " force summaries, the force channels " +
                    std::to_string(channels_.size()));
    for (size_t s = 0; s < channels_.size(); ++s) {
      SURGE_CHECK(peaks[s].faces.size() == channels_[s].faces.size(),
                  "checkpoint summary of '" + channels_[s].name + "' has " +
                      std::to_string(peaks[s].faces.size()) + " faces, its channel has " +
                      std::to_string(channels_[s].faces.size()));
    }
    structures_ = peaks;
    samples_ = samples;
  }

 private:
  void Accumulate(Real time, Real dt, const Vec3& force, Real contact_area, ForcePeak& out) {
    const Real magnitude = force.norm();
    const bool first = std::isnan(out.peak_time);  // no sample with a finite |F| yet
    if (first ? !std::isnan(magnitude) : magnitude > out.peak_force) {
      out.peak_force = magnitude;
      out.peak_time = time;
      out.force_at_peak = force;
    }
    out.impulse += force * dt;
    if (contact_area > out.peak_contact_area) out.peak_contact_area = contact_area;
  }

  std::vector<ForceChannel> channels_;
  std::vector<StructurePeak> structures_;
  int64_t samples_ = 0;
};

}  // namespace surge
