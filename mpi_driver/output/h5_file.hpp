#pragma once
/// \file
/// A small RAII layer over the HDF5 C API for the run output written by the root rank: groups,
/// attributes, fixed datasets and appendable series (an unlimited first dimension that grows by
/// one row per append). Every HDF5 failure becomes a RuntimeFailure naming the file and object.

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace efdem::mpi_driver {

class H5File;

/// A dataset of shape (rows, row_shape...) that grows by one row per append; doubles, 64-bit
/// integers or variable-length strings.
class H5Series {
  public:
    enum class Type { real, integer, text };
    H5Series(H5File& file, const std::string& name, std::vector<hsize_t> row_shape, Type type);
    /// Opens the existing series `name` of `file` to append to it (a restarted run).
    static H5Series open(H5File& file, const std::string& name, Type type);
    ~H5Series();
    H5Series(H5Series&& other) noexcept;
    H5Series& operator=(H5Series&&) = delete;
    H5Series(const H5Series&) = delete;
    H5Series& operator=(const H5Series&) = delete;

    void append(std::span<const double> row);
    void append(std::span<const std::int64_t> row);
    void append(double value) { append(std::span<const double>(&value, 1)); }
    void append_integer(std::int64_t value) { append(std::span<const std::int64_t>(&value, 1)); }
    void append_text(const std::string& text);
    hsize_t rows() const { return rows_; }
    hsize_t row_size() const { return row_size_; }

  private:
    H5Series() = default;
    void extend_and_write(const void* data, hid_t memtype);
    H5File* file_;
    std::string name_;
    std::vector<hsize_t> row_shape_;
    hsize_t row_size_ = 1;
    hid_t dset_ = -1;
    hid_t type_ = -1;
    hsize_t rows_ = 0;
};

class H5File {
  public:
    /// Creates (truncates) `path`.
    static H5File create(const std::filesystem::path& path);
    /// Opens an existing file (serial driver); RuntimeFailure naming the file if it cannot.
    static H5File open(const std::filesystem::path& path, bool writable);
    /// Opens an HDF5 file held in memory (read only; a checkpoint stores the run file whole),
    /// `name` standing for it in messages; RuntimeFailure if `bytes` is not an HDF5 file.
    static H5File open_image(const std::string& bytes, const std::string& name);
    ~H5File();
    H5File(H5File&& other) noexcept;
    H5File& operator=(H5File&&) = delete;
    H5File(const H5File&) = delete;
    H5File& operator=(const H5File&) = delete;

    void create_group(const std::string& path);
    /// Attributes on an existing object ("/" for the file); an existing one is replaced.
    void attribute(const std::string& object, const std::string& name, const std::string& value);
    void attribute(const std::string& object, const std::string& name, double value);
    void attribute(const std::string& object, const std::string& name, std::int64_t value);
    /// The build that writes the file, as attributes of "/": efdem_version, git_hash, build.
    void write_build_provenance();
    /// A fixed dataset of doubles with the given shape (row-major).
    void write(const std::string& name, std::span<const double> data, std::vector<hsize_t> shape);
    /// A scalar variable-length string dataset.
    void write_text(const std::string& name, const std::string& text);
    /// Fixed datasets of 64-bit integers and of bytes (row-major; any shape may have a zero).
    void write(const std::string& name, std::span<const std::int64_t> data,
               std::vector<hsize_t> shape);
    void write_bytes(const std::string& name, std::span<const std::uint8_t> data);
    /// A 1D dataset of variable-length strings.
    void write_texts(const std::string& name, const std::vector<std::string>& texts);
    /// Makes `name` self-describing: attributes `units`, `long_name` and `description`, a label
    /// on each dimension (HDF5 dimension scales), and the axis dataset `scales[i]` attached to
    /// dimension i where it is non-empty and exists; `scales[i] == name` makes `name` itself
    /// that axis (a dimension scale named `labels[i]`).
    void document(const std::string& name, const std::string& units, const std::string& long_name,
                  const std::string& description, const std::vector<std::string>& labels,
                  const std::vector<std::string>& scales);
    /// Removes every dimension scale of the file: no dataset is a scale, has one attached or
    /// labels its dimensions any more (the attributes CLASS, NAME, REFERENCE_LIST,
    /// DIMENSION_LIST, DIMENSION_LABELS go), so that document() can lay them out anew.
    void strip_dimension_scales();
    /// Renames (moves) the link `from` to `to` (a dataset or a group with all it holds).
    void move(const std::string& from, const std::string& to);
    void flush();

    // Reading (checkpoints): RuntimeFailure naming the file and object on any failure.
    bool exists(const std::string& name) const;
    bool has_attribute(const std::string& object, const std::string& name) const;
    std::int64_t attribute_integer(const std::string& object, const std::string& name) const;
    std::string attribute_text(const std::string& object, const std::string& name) const;
    /// Dimensions of a dataset.
    std::vector<hsize_t> shape(const std::string& name) const;
    /// Rows [first, first + count) of a dataset (all of it: first = 0, count = rows), flattened.
    std::vector<double> read_doubles(const std::string& name, hsize_t first = 0,
                                     hsize_t count = ~hsize_t{0}) const;
    std::vector<std::int64_t> read_integers(const std::string& name, hsize_t first = 0,
                                            hsize_t count = ~hsize_t{0}) const;
    std::vector<std::uint8_t> read_bytes(const std::string& name, hsize_t first = 0,
                                         hsize_t count = ~hsize_t{0}) const;
    /// Names of the members of a group, in name order.
    std::vector<std::string> members(const std::string& group) const;
    std::string read_text(const std::string& name) const;

    hid_t id() const { return file_; }
    const std::string& path() const { return path_; }
    /// Throws RuntimeFailure naming the file and `what` when status < 0.
    void check(herr_t status, const std::string& what) const;
    hid_t check_id(hid_t id, const std::string& what) const;

  private:
    H5File(hid_t file, std::string path) : file_(file), path_(std::move(path)) {}
    hid_t file_ = -1;
    std::string path_;
};

}  // namespace efdem::mpi_driver
