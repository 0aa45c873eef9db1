#include "granmem/tracking/track_run.hpp"

#include "granmem/core/error.hpp"

namespace granmem {

std::filesystem::path detections_path(const std::filesystem::path& folder,
                                      const std::filesystem::path& scan) {
  return folder / (scan.filename().stem().string() + ".h5");
}

std::string TrackSummary::Report() const {
  std::string s = linked.Report() + "wrote";
  for (std::size_t k = 0; k < written.size(); ++k)
    s += (k ? (k + 1 == written.size() ? " and " : ", ") : " ") + written[k].string();
  return s + "\n";
}

void TrackRunOptions::validate() const {
  link.validate();
  if (scans.empty()) throw Error("track: no scans");
  for (const std::filesystem::path& scan : scans) {
    if (!std::filesystem::exists(scan)) {
      throw Error("scan " + scan.string() + ": no such file or folder");
    }
  }
  locate.validate();
  if (out.empty()) throw Error("track: no --out (the trajectory store to write)");
}

TrackSummary track_run(const TrackRunOptions& o) {
  o.validate();
  if (!o.detections.empty()) std::filesystem::create_directories(o.detections);
  TrackSummary summary;
  std::vector<Detections> found;
  std::vector<std::string> names;
  for (std::size_t k = 0; k < o.scans.size(); ++k) {
    ScanLocateOptions locate = o.locate;
    locate.frame = o.link.first_cycle + std::int64_t(k);
    LocatedScan s = locate_scan(o.scans[k], locate);
    if (o.log) o.log(s.Report());
    if (!o.detections.empty()) {
      write_detections(s.detections, detections_path(o.detections, o.scans[k]));
    }
    summary.scans.push_back(s.summary);
    found.push_back(std::move(s.detections));
    names.push_back(o.scans[k].string());
  }
  summary.linked = link_run(std::move(found), names, o.link);
  summary.written = write_link_run(summary.linked, o.out, o.report, o.parameters);
  return summary;
}

}  // namespace granmem
