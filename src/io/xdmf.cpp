// XDMF 3 sidecar (xdmf.org, "XDMF Model and Format"): one Uniform Polyvertex grid per snapshot,
// in a Temporal collection; every DataItem points into the .h5 by relative file name, so the
// results folder can be moved or copied as a whole.
#include "io/xdmf.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "io/results_writer.h"

namespace surge {
namespace {

// The text with the five XML special characters replaced by entities.
std::string XmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

void Item(std::ofstream& out, const std::string& h5, const std::string& path, size_t n, int cols,
          const char* type, int precision) {
  out << "        <DataItem Dimensions=\"" << n;
  if (cols > 0) out << " " << cols;
  out << "\" NumberType=\"" << type << "\" Precision=\"" << precision << "\" Format=\"HDF\">"
      << h5 << ":" << path << "</DataItem>\n";
}

void Attribute(std::ofstream& out, const std::string& h5, const std::string& group,
               const char* name, const char* kind, size_t n, int cols, const char* type = "Float",
               int precision = 8) {
  out << "      <Attribute Name=\"" << name << "\" AttributeType=\"" << kind
      << "\" Center=\"Node\">\n";
  Item(out, h5, group + "/" + name, n, cols, type, precision);
  out << "      </Attribute>\n";
}

}  // namespace

void WriteXdmf(const std::string& xmf_path, const std::string& h5_name,
               const std::vector<XdmfSnapshot>& snapshots) {
  const std::string h5 = XmlEscape(h5_name);
  const std::string tmp = xmf_path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw IoError("cannot write '" + tmp + "'");
    out << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n"
        << "    <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (const XdmfSnapshot& s : snapshots) {
      char time[32];
      std::snprintf(time, sizeof time, "%.17g", s.time);
      out << "    <Grid Name=\"" << s.group.substr(s.group.rfind('/') + 1)
          << "\" GridType=\"Uniform\">\n"
          << "      <Time Value=\"" << time << "\"/>\n"
          << "      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << s.particles
          << "\" NodesPerElement=\"1\"/>\n"
          << "      <Geometry GeometryType=\"XYZ\">\n";
      Item(out, h5, s.group + "/position", s.particles, 3, "Float", 8);
      out << "      </Geometry>\n";
      Attribute(out, h5, s.group, "velocity", "Vector", s.particles, 3);
      Attribute(out, h5, s.group, "stress", "Tensor6", s.particles, 6);
      for (const char* scalar : {"pressure", "von_mises", "strain_volumetric", "strain_equivalent"})
        Attribute(out, h5, s.group, scalar, "Scalar", s.particles, 0);
      Attribute(out, h5, s.group, "material", "Scalar", s.particles, 0, "Int", 4);
      Attribute(out, h5, s.group, "body", "Scalar", s.particles, 0, "Int", 4);
      Attribute(out, h5, s.group, "id", "Scalar", s.particles, 0, "Int", 8);
      Attribute(out, h5, s.group, "plastic_strain", "Scalar", s.particles, 0);
      out << "    </Grid>\n";
    }
    out << "    </Grid>\n  </Domain>\n</Xdmf>\n";
    if (!out) throw IoError("cannot write '" + tmp + "'");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, xmf_path, ec);
  if (ec) throw IoError("cannot write '" + xmf_path + "': " + ec.message());
}

}  // namespace surge
