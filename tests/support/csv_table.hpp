#pragma once
/// \file
/// A CSV file as a table of strings, split the plain way (efdem's CSV has no quoted fields):
/// the header row and the data rows, for tests that check what `pandas.read_csv(file)` sees
/// without pandas.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace efdem::test {

struct CsvTable {
    std::vector<std::string> header;             ///< the first line's fields
    std::vector<std::vector<std::string>> rows;  ///< every later line's fields
    /// Rows whose field count differs from the header's (pandas would misalign or refuse them).
    std::size_t ragged_rows() const {
        std::size_t n = 0;
        for (const auto& r : rows) n += r.size() != header.size();
        return n;
    }
};

/// The whole text of a file ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

inline std::vector<std::string> csv_fields(const std::string& line) {
    std::vector<std::string> out;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
    if (!line.empty() && line.back() == ',') out.emplace_back();
    return out;
}

inline CsvTable read_csv_table(const std::filesystem::path& file) {
    std::ifstream in(file);
    CsvTable t;
    std::string line;
    if (std::getline(in, line)) t.header = csv_fields(line);
    while (std::getline(in, line)) t.rows.push_back(csv_fields(line));
    return t;
}

}  // namespace efdem::test
