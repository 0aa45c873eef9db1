#include "tiff_metadata.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <map>

#include "granmem/core/error.hpp"
#include "granmem/core/units.hpp"

namespace granmem::stack_io {
namespace {

std::string lower(std::string_view text) {
  std::string out(text);
  for (char& c : out)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::optional<double> parse_number(std::string_view text) {
  text = trim(text);
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

// TIFF rationals reach us through libtiff as float: 1/XResolution carries about 7
// significant digits. Rounding to 6 recovers the size that was written (0.075, not
// 0.07500000187).
double round_float_precision(double value) {
  char buffer[32];
  const auto [end, ec] =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, 6);
  (void)ec;
  double rounded = value;
  std::from_chars(buffer, end, rounded);
  return rounded;
}

// "key=value" lines of an ImageJ description.
std::map<std::string, std::string> imagej_fields(std::string_view description) {
  std::map<std::string, std::string> fields;
  while (!description.empty()) {
    const std::size_t end = description.find('\n');
    const std::string_view line = description.substr(0, end);
    const std::size_t eq = line.find('=');
    if (eq != std::string_view::npos) {
      fields[std::string(trim(line.substr(0, eq)))] = std::string(trim(line.substr(eq + 1)));
    }
    if (end == std::string_view::npos) break;
    description.remove_prefix(end + 1);
  }
  return fields;
}

// A count the metadata declare (channels, slices, frames, images); 0 where they say none.
// One beyond any stack (2e30 slices) is refused here: it would not fit an integer. `where`:
// the file and the metadata's kind, for the message.
std::int64_t count_field(const std::map<std::string, std::string>& fields, const char* key,
                         const std::string& where) {
  const auto it = fields.find(key);
  if (it == fields.end()) return 0;
  const auto value = parse_number(it->second);
  if (!value || !(*value >= 0)) return 0;
  if (*value > 1e15) {
    throw Error(where + " declares " + key + "=" + it->second + ", beyond any stack");
  }
  return static_cast<std::int64_t>(*value);
}

// One scan is one channel and, if it is a z stack, one time frame.
void check_single_scan(const TiffFile& file, const char* format, std::int64_t channels,
                       std::int64_t slices, std::int64_t frames) {
  if (channels > 1) {
    throw Error(file.name() + ": " + format + " hyperstack of " + std::to_string(channels) +
                " channels, expected one channel (split the channels first)");
  }
  if (frames > 1 && slices > 1) {
    throw Error(file.name() + ": " + format + " hyperstack of " + std::to_string(frames) +
                " time frames of " + std::to_string(slices) +
                " slices, expected one scan (one frame per file)");
  }
}

TiffMetadata imagej_metadata(const TiffFile& file, std::string_view description) {
  const auto fields = imagej_fields(description);
  const std::string where = file.name() + ": ImageJ metadata";
  check_single_scan(file, "ImageJ", count_field(fields, "channels", where),
                    count_field(fields, "slices", where), count_field(fields, "frames", where));
  TiffMetadata meta;
  meta.imagej_images = count_field(fields, "images", where);

  // ImageJ's unit: the description's, else the TIFF resolution unit (inch or cm).
  std::optional<LengthUnit> unit;
  if (const auto it = fields.find("unit"); it != fields.end()) {
    unit = parse_length_unit(it->second);
  } else {
    std::uint16_t resolution_unit = RESUNIT_NONE;
    TIFFGetField(file.get(), TIFFTAG_RESOLUTIONUNIT, &resolution_unit);
    if (resolution_unit == RESUNIT_INCH) unit = parse_length_unit("inch");
    if (resolution_unit == RESUNIT_CENTIMETER) unit = parse_length_unit("cm");
  }
  if (!unit) return meta;

  // As ImageJ: a size not given is 1 (in the unit); XResolution is pixels per unit.
  Eigen::Vector3d size(1, 1, 1);
  float resolution = 0;
  if (TIFFGetField(file.get(), TIFFTAG_XRESOLUTION, &resolution) && resolution > 0) {
    size.x() = round_float_precision(1.0 / resolution);
  }
  if (TIFFGetField(file.get(), TIFFTAG_YRESOLUTION, &resolution) && resolution > 0) {
    size.y() = round_float_precision(1.0 / resolution);
  }
  if (const auto it = fields.find("spacing"); it != fields.end()) {
    if (const auto spacing = parse_number(it->second); spacing && *spacing > 0) {
      size.z() = *spacing;
    }
  }
  meta.voxel_size = size * unit->factor;
  meta.unit = unit->unit;
  return meta;
}

void append_utf8(std::string& out, unsigned long code) {
  if (code < 0x80) {
    out += static_cast<char>(code);
  } else if (code < 0x800) {
    out += static_cast<char>(0xC0 | (code >> 6));
    out += static_cast<char>(0x80 | (code & 0x3F));
  } else {
    out += static_cast<char>(0xE0 | ((code >> 12) & 0x0F));
    out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (code & 0x3F));
  }
}

// XML attribute text with its entities (&amp;, &#181;, &#xB5;) replaced.
std::string decode_entities(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const std::size_t semi = text[i] == '&' ? text.find(';', i) : std::string_view::npos;
    if (semi == std::string_view::npos || semi - i > 10) {
      out += text[i];
      continue;
    }
    const std::string_view entity = text.substr(i + 1, semi - i - 1);
    if (entity == "amp")
      out += '&';
    else if (entity == "lt")
      out += '<';
    else if (entity == "gt")
      out += '>';
    else if (entity == "quot")
      out += '"';
    else if (entity == "apos")
      out += '\'';
    else if (entity.size() > 1 && entity[0] == '#') {
      const bool hex = entity[1] == 'x' || entity[1] == 'X';
      unsigned long code = 0;
      const char* first = entity.data() + (hex ? 2 : 1);
      std::from_chars(first, entity.data() + entity.size(), code, hex ? 16 : 10);
      append_utf8(out, code);
    } else {
      out += text.substr(i, semi - i + 1);
    }
    i = semi;
  }
  return out;
}

// The attributes of the first <Pixels> element (any namespace prefix) of an OME document.
std::map<std::string, std::string> ome_pixels_attributes(std::string_view xml) {
  std::map<std::string, std::string> attributes;
  std::size_t at = 0;
  for (;; at += 6) {
    at = xml.find("Pixels", at);
    if (at == std::string_view::npos) return attributes;
    std::size_t start = at;  // back over a prefix ("ome:") to the '<'
    while (start > 0 && (std::isalnum(static_cast<unsigned char>(xml[start - 1])) ||
                         xml[start - 1] == ':' || xml[start - 1] == '_')) {
      --start;
    }
    const bool prefixed = start < at && xml[at - 1] == ':';
    if (start > 0 && xml[start - 1] == '<' && (start == at || prefixed) && at + 6 < xml.size() &&
        (std::isspace(static_cast<unsigned char>(xml[at + 6])) || xml[at + 6] == '>' ||
         xml[at + 6] == '/')) {
      break;
    }
  }
  std::size_t i = at + 6;
  while (i < xml.size() && xml[i] != '>' && xml[i] != '/') {
    if (std::isspace(static_cast<unsigned char>(xml[i]))) {
      ++i;
      continue;
    }
    const std::size_t eq = xml.find('=', i);
    if (eq == std::string_view::npos || eq + 1 >= xml.size()) break;
    const std::string name(trim(xml.substr(i, eq - i)));
    std::size_t q = eq + 1;
    while (q < xml.size() && std::isspace(static_cast<unsigned char>(xml[q])))
      ++q;
    if (q >= xml.size() || (xml[q] != '"' && xml[q] != '\'')) break;
    const std::size_t close = xml.find(xml[q], q + 1);
    if (close == std::string_view::npos) break;
    attributes[name] = decode_entities(xml.substr(q + 1, close - q - 1));
    i = close + 1;
  }
  return attributes;
}

TiffMetadata ome_metadata(const TiffFile& file, std::string_view xml) {
  const auto pixels = ome_pixels_attributes(xml);
  const std::string where = file.name() + ": OME metadata";
  check_single_scan(file, "OME", count_field(pixels, "SizeC", where),
                    count_field(pixels, "SizeZ", where), count_field(pixels, "SizeT", where));

  // Each axis has its own unit, micrometres when not given (the OME schema's default);
  // all three are needed, in the unit of x.
  TiffMetadata meta;
  Eigen::Vector3d size;
  std::string unit;
  const char* axes[] = {"X", "Y", "Z"};
  for (int a = 0; a < 3; ++a) {
    const std::string key = std::string("PhysicalSize") + axes[a];
    const auto value = pixels.find(key);
    if (value == pixels.end()) return meta;
    const auto number = parse_number(value->second);
    const auto unit_text = pixels.find(key + "Unit");
    const auto axis_unit =
        parse_length_unit(unit_text == pixels.end() ? "um" : std::string_view(unit_text->second));
    if (!number || *number <= 0 || !axis_unit) return meta;
    if (a == 0) unit = axis_unit->unit;
    size[a] = convert_length(*number * axis_unit->factor, axis_unit->unit, unit);
  }
  meta.voxel_size = size;
  meta.unit = unit;
  return meta;
}

}  // namespace

std::optional<LengthUnit> parse_length_unit(std::string_view text) {
  const std::string name = lower(trim(text));
  struct Spelling {
    const char* name;
    const char* unit;
    double factor;
  };
  static const Spelling spellings[] = {
      {"m", "m", 1},
      {"meter", "m", 1},
      {"metre", "m", 1},
      {"meters", "m", 1},
      {"metres", "m", 1},
      {"cm", "cm", 1},
      {"centimeter", "cm", 1},
      {"centimetre", "cm", 1},
      {"centimeters", "cm", 1},
      {"centimetres", "cm", 1},
      {"mm", "mm", 1},
      {"millimeter", "mm", 1},
      {"millimetre", "mm", 1},
      {"millimeters", "mm", 1},
      {"millimetres", "mm", 1},
      {"um", "um", 1},
      {"micron", "um", 1},
      {"microns", "um", 1},
      {"micrometer", "um", 1},
      {"micrometre", "um", 1},
      {"micrometers", "um", 1},
      {"micrometres", "um", 1},
      {"\xC2\xB5m", "um", 1},  // UTF-8 micro sign
      {"\xCE\xBCm", "um", 1},  // UTF-8 Greek mu
      {"\xB5m", "um", 1},      // Latin-1 micro sign
      {"\\u00b5m", "um", 1},   // ImageJ's escape
      {"nm", "um", 1e-3},
      {"nanometer", "um", 1e-3},
      {"nanometre", "um", 1e-3},
      {"nanometers", "um", 1e-3},
      {"nanometres", "um", 1e-3},
      {"inch", "mm", 25.4},
      {"inches", "mm", 25.4},
      {"in", "mm", 25.4},
  };
  for (const Spelling& s : spellings) {
    if (name == s.name) return LengthUnit{s.unit, s.factor};
  }
  return std::nullopt;  // pixel, missing or a unit granmem does not measure lengths in
}

TiffMetadata read_tiff_metadata(const TiffFile& file) {
  const char* text = nullptr;
  if (!TIFFGetField(file.get(), TIFFTAG_IMAGEDESCRIPTION, &text) || !text) return {};
  const std::string_view description(text);
  if (description.rfind("ImageJ=", 0) == 0) return imagej_metadata(file, description);
  if (description.find("<OME") != std::string_view::npos ||
      description.find(":OME") != std::string_view::npos) {
    return ome_metadata(file, description);
  }
  return {};
}

std::string shortest_text(double value) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  (void)ec;
  return std::string(buffer, end);
}

std::string imagej_description(const Stack& stack) {
  // "1.11a": the oldest version that reads these fields, as other writers put it.
  std::string text = "ImageJ=1.11a\n";
  if (stack.nz > 1) {
    text += "images=" + std::to_string(stack.nz) + "\n";
    text += "slices=" + std::to_string(stack.nz) + "\n";
  }
  if (stack.voxel_size) {
    // ImageJ writes micrometres as "micron", keeping the description ASCII.
    text += "unit=" + (stack.unit == "um" ? std::string("micron") : stack.unit) + "\n";
    text += "spacing=" + shortest_text(stack.voxel_size->z()) + "\n";
  }
  text += "loop=false\n";
  return text;
}

}  // namespace granmem::stack_io
