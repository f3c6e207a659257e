#include "dem/io/lammps_data.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <system_error>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"

namespace efdem::dem {

namespace {

/// Line reader over gzip or plain files (zlib reads both transparently).
class GzLines {
  public:
    explicit GzLines(const std::filesystem::path& path) : path_(path.string()) {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec))
            throw InputError({path_, 0}, "LAMMPS data file not found");
        file_ = gzopen(path_.c_str(), "rb");
        if (!file_) throw InputError({path_, 0}, "cannot be opened for reading");
    }
    ~GzLines() {
        if (file_) gzclose(file_);
    }
    GzLines(const GzLines&) = delete;
    GzLines& operator=(const GzLines&) = delete;

    bool next(std::string& line) {
        line.clear();
        char buf[4096];
        while (gzgets(file_, buf, sizeof buf)) {
            line += buf;
            if (!line.empty() && line.back() == '\n') break;
        }
        int err = 0;
        gzerror(file_, &err);
        if (err != Z_OK && err != Z_STREAM_END)
            throw InputError({path_, line_ + 1}, "is corrupt or truncated (gzip error)");
        if (line.empty()) return false;
        ++line_;
        if (line.back() == '\n') line.pop_back();
        if (!line.empty() && line.back() == '\r') line.pop_back();
        return true;
    }
    int line_number() const { return line_; }
    const std::string& path() const { return path_; }

  private:
    std::string path_;
    gzFile file_ = nullptr;
    int line_ = 0;
};

std::string strip(const std::string& s) {
    std::string t = s.substr(0, s.find('#'));
    const auto b = t.find_first_not_of(" \t");
    if (b == std::string::npos) return "";
    const auto e = t.find_last_not_of(" \t");
    return t.substr(b, e - b + 1);
}

std::vector<double> numbers(const std::string& line, std::size_t want, const GzLines& in,
                            const char* what) {
    std::istringstream ss(line);
    std::vector<double> out;
    std::string tok;
    while (ss >> tok) {
        try {
            std::size_t used = 0;
            out.push_back(std::stod(tok, &used));
            if (used != tok.size()) throw std::invalid_argument(tok);
        } catch (const std::exception&) {
            throw InputError({in.path(), in.line_number()},
                             fmt::format("'{}' in a {} line is not a number", tok, what));
        }
        if (!std::isfinite(out.back()))
            throw InputError({in.path(), in.line_number()},
                             fmt::format("non-finite value in a {} line", what));
    }
    if (out.size() < want)
        throw InputError(
            {in.path(), in.line_number()},
            fmt::format("a {} line needs at least {} numbers, has {}", what, want, out.size()));
    return out;
}

/// Largest atom id: ids are read as doubles, which hold every integer up to 2^53 exactly.
constexpr long kMaxAtomId = 1L << 53;

/// A whole number in [lo, hi] from a value read as a double (ids, types, counts); InputError
/// naming `what` otherwise (a double outside the range of the integer is not converted).
long whole_number(double v, long lo, long hi, const GzLines& in, const std::string& what) {
    if (!(std::trunc(v) == v && v >= static_cast<double>(lo) && v <= static_cast<double>(hi)))
        throw InputError(
            {in.path(), in.line_number()},
            fmt::format("{} is {:g}; it must be a whole number from {} to {}", what, v, lo, hi));
    return static_cast<long>(v);
}

}  // namespace

Particles read_lammps_data(const std::filesystem::path& file, const SpeciesTable& species,
                           const Domain& domain) {
    GzLines in(file);
    std::string line;
    in.next(line);  // the first line is a title
    long n_atoms = -1;
    double box[3][2] = {{0, 0}, {0, 0}, {0, 0}};
    bool have_box[3] = {false, false, false};
    struct Atom {
        Tag id;
        SpeciesId type;
        Vec3 x, v, w;
    };
    std::vector<Atom> atoms;
    std::unordered_map<Tag, std::size_t> index_of;
    long n_types = -1;
    bool have_labels = false;
    std::string section;
    while (in.next(line)) {
        const std::string s = strip(line);
        if (s.empty()) continue;
        const bool is_number = std::isdigit(static_cast<unsigned char>(s[0])) || s[0] == '-' ||
                               s[0] == '+' || s[0] == '.';
        if (!is_number) {  // a section keyword
            section = s.rfind("Atom Type Labels", 0) == 0 ? std::string("Atom Type Labels")
                                                          : s.substr(0, s.find_first_of(" \t"));
            if (section == "Atoms" && line.find("sphere") == std::string::npos &&
                line.find('#') != std::string::npos)
                throw InputError({in.path(), in.line_number()},
                                 "the Atoms section is not of atom_style sphere");
            continue;
        }
        if (section.empty()) {  // header
            if (s.find("atom types") != std::string::npos)
                n_types =
                    whole_number(numbers(s.substr(0, s.find("atom types")), 1, in, "atom types")[0],
                                 1, 255, in, "the number of atom types");
            if (s.find("atoms") != std::string::npos)
                n_atoms = whole_number(numbers(s.substr(0, s.find("atoms")), 1, in, "atoms")[0], 0,
                                       kMaxRealizationParticles, in, "the number of atoms");
            for (int a = 0; a < 3; ++a) {
                const char* lo = a == 0 ? "xlo" : a == 1 ? "ylo" : "zlo";
                if (s.find(lo) != std::string::npos) {
                    const auto v = numbers(s.substr(0, s.find(lo)), 2, in, "box");
                    box[a][0] = v[0];
                    box[a][1] = v[1];
                    have_box[a] = true;
                }
            }
        } else if (section == "Atom Type Labels") {  // `type name`: the species' names
            std::istringstream ss(s);
            std::string type_text, label;
            ss >> type_text >> label;
            const long type = whole_number(numbers(type_text, 1, in, "Atom Type Labels")[0], 1, 255,
                                           in, "the labelled atom type");
            if (type > static_cast<long>(species.size()) ||
                label != species[static_cast<SpeciesId>(type - 1)].name)
                throw InputError(
                    {in.path(), in.line_number()},
                    fmt::format(
                        "atom type {} is labelled '{}', but the scene's species {} is {} "
                        "(species.names: type t is the t-th name)",
                        type, label, type,
                        type > static_cast<long>(species.size())
                            ? std::string("not there")
                            : fmt::format("'{}'", species[static_cast<SpeciesId>(type - 1)].name)));
            have_labels = true;
        } else if (section == "Atoms") {
            const auto v = numbers(s, 7, in, "Atoms");
            const auto id = static_cast<Tag>(whole_number(v[0], 1, kMaxAtomId, in, "the atom id"));
            const long type = whole_number(v[1], 1, 255, in, "the atom type");
            if (type > static_cast<long>(species.size()))
                throw InputError(
                    {in.path(), in.line_number()},
                    fmt::format("atom type {} has no species: species.names lists {} species", type,
                                species.size()));
            if (static_cast<long>(atoms.size()) >= kMaxRealizationParticles)
                throw InputError(
                    {in.path(), in.line_number()},
                    fmt::format("more than {} atoms; one realization holds at most that many",
                                kMaxRealizationParticles));
            const auto sp = static_cast<SpeciesId>(type - 1);
            const double d = v[2], rho = v[3];
            if (std::abs(d - species[sp].diameter) > 1e-9 * species[sp].diameter ||
                std::abs(rho - species[sp].density) > 1e-9 * species[sp].density)
                throw InputError(
                    {in.path(), in.line_number()},
                    fmt::format(
                        "atom {} of type {} has diameter {} and density {}, but species '{}' has "
                        "diameter {} and density {}",
                        id, type, d, rho, species[sp].name, species[sp].diameter,
                        species[sp].density));
            const double z = v[6];
            if (z < 0 || z > (domain.has_lid() ? domain.lid_height : kMaxDomainLength))
                throw InputError(
                    {in.path(), in.line_number()},
                    fmt::format(
                        "atom {} is at z = {:g}, outside the domain (allowed: 0 <= z <= {:g})", id,
                        z, domain.has_lid() ? domain.lid_height : kMaxDomainLength));
            if (index_of.count(id))
                throw InputError({in.path(), in.line_number()},
                                 fmt::format("atom id {} appears twice", id));
            index_of.emplace(id, atoms.size());
            atoms.push_back({id, sp, {v[4], v[5], v[6]}, {}, {}});
        } else if (section == "Velocities") {
            const auto v = numbers(s, 7, in, "Velocities");
            const auto it = index_of.find(
                static_cast<Tag>(whole_number(v[0], 1, kMaxAtomId, in, "the atom id")));
            if (it == index_of.end())
                throw InputError({in.path(), in.line_number()},
                                 "velocity of an atom id not in the Atoms section");
            atoms[it->second].v = {v[1], v[2], v[3]};
            atoms[it->second].w = {v[4], v[5], v[6]};
        }
    }
    if (n_atoms < 0)
        throw InputError({in.path(), 0}, "the header does not give the number of atoms");
    if (have_labels && n_types != static_cast<long>(species.size()))
        throw InputError({in.path(), 0},
                         fmt::format("the file has {} atom types (species), but species.names "
                                     "lists {}",
                                     n_types, species.size()));
    if (static_cast<long>(atoms.size()) != n_atoms)
        throw InputError({in.path(), 0},
                         fmt::format("the header announces {} atoms but the Atoms section "
                                     "has {} (truncated file?)",
                                     n_atoms, atoms.size()));
    for (int a = 0; a < 2; ++a) {
        const double want = a == 0 ? domain.lx : domain.ly;
        if (!have_box[a] || std::abs(box[a][0]) > 1e-12 || std::abs(box[a][1] - want) > 1e-9 * want)
            throw InputError(
                {in.path(), 0},
                fmt::format(
                    "the box in {} is [{}, {}], but domain.{} = {} (the box must start at 0)",
                    a == 0 ? "x" : "y", box[a][0], box[a][1], a == 0 ? "lx" : "ly", want));
    }
    // A deterministic particle order: by id.
    std::sort(atoms.begin(), atoms.end(), [](const Atom& a, const Atom& b) { return a.id < b.id; });
    Particles p;
    p.reserve(atoms.size());
    for (const auto& a : atoms) {
        p.add(a.id, domain.wrap(a.x), a.v, a.type, species);
        p.omega()[p.size() - 1] = a.w;
    }
    return p;
}

void write_lammps_data(const std::filesystem::path& file, const Particles& p,
                       const SpeciesTable& species, const Domain& domain,
                       const std::string& title) {
    std::vector<std::size_t> order(p.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return p.tag()[a] < p.tag()[b]; });
    double top = 0;
    for (std::size_t i = 0; i < p.size(); ++i) top = std::max(top, p.x()[i].z + p.radius()[i]);
    const double zhi = domain.has_lid() ? domain.lid_height : top;
    std::string text = fmt::format(
        "{}\n\n{} atoms\n{} atom types\n\n0 {:.17g} xlo xhi\n0 {:.17g} ylo yhi\n0 {:.17g} zlo "
        "zhi\n\nAtom Type Labels\n\n",
        title, p.size(), species.size(), domain.lx, domain.ly, zhi);
    for (std::size_t s = 0; s < species.size(); ++s)
        text += fmt::format("{} {}\n", s + 1, species[static_cast<SpeciesId>(s)].name);
    text += "\nAtoms # sphere\n\n";
    for (std::size_t i : order) {
        const Species& sp = species[p.species()[i]];
        const Vec3 x = domain.wrap(p.x()[i]);
        text += fmt::format("{} {} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}\n", p.tag()[i],
                            p.species()[i] + 1, sp.diameter, sp.density, x.x, x.y, x.z);
    }
    text += "\nVelocities\n\n";
    for (std::size_t i : order) {
        const Vec3 v = p.v()[i], w = p.omega()[i];
        text += fmt::format("{} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}\n", p.tag()[i], v.x,
                            v.y, v.z, w.x, w.y, w.z);
    }
    const std::string name = file.string();
    const std::string tmp = name + ".tmp";
    auto fail = [&](const std::string& why) {
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw RuntimeFailure(fmt::format("cannot write the bed file {}: {}", name, why));
    };
    if (const auto parent = file.parent_path(); !parent.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(parent, ec);
        if (ec) fail(fmt::format("its folder cannot be created ({})", ec.message()));
    }
    if (name.ends_with(".gz")) {
        gzFile g = gzopen(tmp.c_str(), "wb");
        if (!g) fail("cannot open it");
        const bool ok = gzwrite(g, text.data(), static_cast<unsigned>(text.size())) ==
                        static_cast<int>(text.size());
        if (gzclose(g) != Z_OK || !ok) fail("write error (disk full?)");
    } else {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) fail("cannot open it");
        out.write(text.data(), static_cast<std::streamsize>(text.size()));
        out.close();
        if (!out) fail("write error (disk full?)");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, file, ec);
    if (ec) fail(ec.message());
}

std::filesystem::path realization_file(const std::filesystem::path& name, long realization) {
    std::string leaf = name.filename().string();
    std::string gz;
    if (leaf.size() > 3 && leaf.ends_with(".gz")) {
        gz = ".gz";
        leaf.resize(leaf.size() - 3);
    }
    const std::filesystem::path base(leaf);
    const std::string ext = base.extension().string();
    const std::string stem = leaf.substr(0, leaf.size() - ext.size());
    return name.parent_path() / fmt::format("{}_r{:04d}{}{}", stem, realization, ext, gz);
}

}  // namespace efdem::dem
