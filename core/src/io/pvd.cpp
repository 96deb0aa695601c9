#include "strata/core/io/pvd.hpp"

#include <ostream>

#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/number_text.hpp"
#include "vtk_xml.hpp"

namespace strata {

PvdWriter::PvdWriter(std::filesystem::path pvd_path) : m_path(std::move(pvd_path)) {
  write();
}

void PvdWriter::add_frame(double time, const std::string& file, int part) {
  m_entries.push_back({time, file, part});
  try {
    write();
  } catch (...) {
    m_entries.pop_back();
    throw;
  }
}

void PvdWriter::write() const {
  write_file_atomically(m_path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
           "  <Collection>\n";
    for (const PvdEntry& entry : m_entries) {
      out << "    <DataSet timestep=\"";
      write_double(out, entry.time);
      out << "\" group=\"\" part=\"" << entry.part << "\" file=\"";
      out << vtk_xml::escape(entry.file);
      out << "\"/>\n";
    }
    out << "  </Collection>\n</VTKFile>\n";
  });
}

}  // namespace strata
