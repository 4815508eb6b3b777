// Force-analysis settings (issue #6): what `surge forces` and the end of `surge run` analyse and
// with which reference values (scene section `analysis`, docs/scene-reference.md). Plain data;
// the analysis itself is src/forces/force_analysis.h (seed spec §5.4-5.6).
#pragma once
#include <array>
#include <optional>
#include <string>

#include "core/math.h"

namespace surge {

// Which scalar of the force vector F is analysed.
enum class ForceComponent {
  kX,
  kY,
  kZ,
  kNormal,    // F . (-n), n the outward normal of an axis face (x-, ..., z+): push on the face > 0
  kMagnitude  // |F|
};

enum class SmoothingKind {
  kNone,
  kMovingAverage,  // centred time average over `window` [s]
  kExponential,    // first-order low-pass with time constant `time_constant` [s]
  kLowPass         // Butterworth of `order` 1 or 2, cut-off `cutoff` [Hz], forward and backward
};

struct SmoothingSettings {
  SmoothingKind kind = SmoothingKind::kNone;
  Real window = 0;         // kMovingAverage: full width [s]
  Real time_constant = 0;  // kExponential: tau [s]
  Real cutoff = 0;         // kLowPass: cut-off frequency [Hz]
  int order = 2;           // kLowPass: 1 or 2 (each pass; zero phase, twice the order overall)
};

// Steady state: the seed's impulse-preserving moving average (Mast 2013 §7.4.2; seed spec §5.5)
// and the plateau at the end of the run.
struct SteadyStateSettings {
  Real average = 0.1;     // width of the impulse-preserving moving average [s]
  Real min_window = 0.5;  // shortest plateau that counts [s]
  Real tolerance = 0.02;  // every averaged sample within tolerance * |mean| of the plateau mean [-]
  std::optional<std::array<Real, 2>> window;  // explicit [t0, t1] [s] instead of detection
};

// Reference values of the coefficients (seed eqs. 7.14-7.19). Unset = not known: the
// coefficients that need them are omitted, with a note.
struct ReferenceValues {
  std::optional<Real> velocity;  // v0, impact velocity [m/s]
  std::optional<Real> density;   // rho0 [kg/m^3]
  std::optional<Real> width;     // w_c, column width across the flow [m] (2-D: 1, per metre)
  std::optional<Real> height;    // H_b, initial flow depth [m]
  std::optional<Real> area;      // A in f = rho0 v^2 A C [m^2]; default w_c H_b
  std::optional<Real> k0;        // at-rest earth pressure coefficient K0 [-]
  std::optional<Real> gravity;   // |g| [m/s^2]
};

struct AnalysisSettings {
  std::string structure;  // structure in the force log; "" = the first obstacle, else sensor, else domain
  std::string face;       // one of its faces; "" = the whole structure
  std::optional<ForceComponent> component;  // unset: normal for an axis face, else magnitude
  ReferenceValues reference;
  SmoothingSettings smoothing;
  SteadyStateSettings steady_state;
};

}  // namespace surge
