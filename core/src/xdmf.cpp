#include "granmem/core/xdmf.hpp"

#include <fstream>
#include <sstream>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"

namespace granmem {

std::filesystem::path xdmf_path(const std::filesystem::path& h5_path) {
  std::filesystem::path p = h5_path;
  return p.replace_extension(".xmf");
}

namespace {

std::string join(const std::vector<std::size_t>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i)
    s += (i ? " " : "") + std::to_string(v[i]);
  return s;
}

// Frame t of a [T, frame_dims...] dataset as an XDMF hyperslab (nothing is copied).
std::string slab(const std::string& ref, std::size_t t, std::size_t frames,
                 const std::vector<std::size_t>& frame_dims, const char* number_type,
                 int precision) {
  std::vector<std::size_t> start(frame_dims.size() + 1, 0), stride(frame_dims.size() + 1, 1);
  std::vector<std::size_t> count{1}, full{frames};
  start[0] = t;
  count.insert(count.end(), frame_dims.begin(), frame_dims.end());
  full.insert(full.end(), frame_dims.begin(), frame_dims.end());
  std::ostringstream s;
  s << "<DataItem ItemType=\"HyperSlab\" Dimensions=\"" << join(frame_dims) << "\">\n"
    << "  <DataItem Dimensions=\"3 " << full.size() << "\" Format=\"XML\">" << join(start) << "  "
    << join(stride) << "  " << join(count) << "</DataItem>\n"
    << "  <DataItem Dimensions=\"" << join(full) << "\" NumberType=\"" << number_type
    << "\" Precision=\"" << precision << "\" Format=\"HDF\">" << ref << "</DataItem>\n"
    << "</DataItem>\n";
  return s.str();
}

std::string whole(const std::string& ref, std::size_t n, const char* number_type, int precision) {
  std::ostringstream s;
  s << "<DataItem Dimensions=\"" << n << "\" NumberType=\"" << number_type << "\" Precision=\""
    << precision << "\" Format=\"HDF\">" << ref << "</DataItem>\n";
  return s.str();
}

std::string attribute(const char* name, const char* type, const std::string& data) {
  return std::string("<Attribute Name=\"") + name + "\" AttributeType=\"" + type +
         "\" Center=\"Node\">\n" + data + "</Attribute>\n";
}

std::string xml_escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

AtomicFile write_xdmf(const std::filesystem::path& h5_path, const std::string& group,
                      const RunHeader& header, const std::vector<std::int64_t>& steps,
                      const std::vector<double>& times) {
  // The sidecar sits beside the file and refers to it by name, so the pair can be moved.
  const std::string ref = xml_escaped(h5_path.filename().string() + ":" + group);
  const std::size_t n = header.grain_count(), frames = steps.size();
  std::ostringstream x;
  x.precision(17);
  x << "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
    << "<Xdmf Version=\"2.0\">\n<Domain>\n"
    << "<Grid Name=\"grains\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t t = 0; t < frames; ++t) {
    x << "<Grid Name=\"step " << steps[t] << "\" GridType=\"Uniform\">\n"
      << "<Time Value=\"" << times[t] << "\"/>\n"
      << "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n << "\"/>\n"
      << "<Geometry GeometryType=\"XYZ\">\n"
      << slab(ref + "/position/value", t, frames, {n, 3}, "Float", 8) << "</Geometry>\n"
      << attribute("radius", "Scalar", whole(ref + "/radius", n, "Float", 8))
      << attribute("id", "Scalar", whole(ref + "/id", n, "Int", 8));
    if (header.has_axis) {
      x << attribute("axis", "Vector", slab(ref + "/axis/value", t, frames, {n, 3}, "Float", 8));
    }
    if (header.has_hole_contact) {
      x << attribute("hole_contact", "Scalar",
                     slab(ref + "/hole_contact/value", t, frames, {n}, "UChar", 1));
    }
    if (header.has_position_error) {
      x << attribute("position_error", "Vector",
                     slab(ref + "/position_error/value", t, frames, {n, 3}, "Float", 8));
    }
    if (header.has_axis_error) {
      x << attribute("axis_error", "Scalar",
                     slab(ref + "/axis_error/value", t, frames, {n}, "Float", 8));
    }
    x << "</Grid>\n";
  }
  x << "</Grid>\n</Domain>\n</Xdmf>\n";

  AtomicFile out(xdmf_path(h5_path));
  {
    std::ofstream f(out.temp_path());
    f << x.str();
    if (!f) throw Error(out.target().string() + ": cannot write the XDMF sidecar");
  }
  return out;
}

}  // namespace granmem
