#pragma once
// A thin RAII layer over the HDF5 C API: just what arcwheel's readers and writers need.
// Every failure throws Error naming the file and the object; HDF5's own error stack printing
// is switched off so that the user sees one clear message.

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace arcwheel::hdf5 {

// Owns one hid_t and closes it with the matching H5*close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(Handle&& other) noexcept : id_(other.id_), closer_(other.closer_) { other.id_ = -1; }
  Handle& operator=(Handle&& other) noexcept;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle();
  [[nodiscard]] hid_t id() const { return id_; }
  [[nodiscard]] bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = -1;
  Closer closer_ = nullptr;
};

// libhdf5 1.10.8 can still crash or hang on some damaged files, inside the library and before any
// check of ours can look at them (docs/known_issues.md). So a reader of a user's file first runs
// `read` in a child process: if the child dies or has not finished after `timeout_s` (0: one
// minute plus one second per 10 MB of file), the file is refused with Error{kBadInput} naming it.
// Otherwise this returns and the caller reads the file itself; a file the reader refuses is refused
// again there, with the reader's own message. Called again inside the child, it returns at once.
void ReadFirstInChildProcess(const std::filesystem::path& path, const std::function<void()>& read,
                             double timeout_s = 0.0);

// Where a dataset's values lie in its file, as bytes from the file's start (user block included).
struct FileExtent {
  std::uint64_t offset = 0;
  std::uint64_t count = 0;  // values
};

// Arrays that a child process fills in place and its parent then takes, through an anonymous
// memory file (Linux memfd): a large dataset is read once, in the child, and never held twice in
// full (the parent gives the shared pages back as it copies them out). A dataset stored as the
// parent wants it (contiguous float32, File::ContiguousFloat32Extent) is not read at all: the
// child checks the file and says where the values lie, and the parent maps those pages of the
// file.
class SharedArrays {
 public:
  SharedArrays();  // Error{kIo} when the memory file cannot be made
  ~SharedArrays();
  SharedArrays(const SharedArrays&) = delete;
  SharedArrays& operator=(const SharedArrays&) = delete;

  // In the child: room for `count` values under `name` (at most 8 arrays, names under 32 bytes).
  template <typename T>
  [[nodiscard]] std::span<T> Allocate(const std::string& name, std::size_t count) {
    return {static_cast<T*>(Allocate(name, count, sizeof(T))), count};
  }
  // In the child: the values of T under `name` are those at `extent` of the file being read.
  template <typename T>
  void LeaveInFile(const std::string& name, const FileExtent& extent) {
    LeaveInFile(name, extent, sizeof(T));
  }
  // In the parent, after ReadInChildProcess returned true: the array the child stored under
  // `name` as values of T, mapped into this process (the child's own pages, or the file's pages
  // in the page cache, copied only where this process writes; not a copy) and kept mapped while
  // `mapping` lives; nothing when it stored none such. Error{kBadInput} when the file was
  // replaced or changed size since the child read it.
  template <typename T>
  struct Mapped {
    std::span<T> values;
    std::shared_ptr<void> mapping;
  };
  template <typename T>
  [[nodiscard]] std::optional<Mapped<T>> Map(const std::string& name) {
    const Entry* entry = Find(name, sizeof(T));
    if (entry == nullptr) return std::nullopt;
    std::shared_ptr<void> mapping = Map(*entry);
    return Mapped<T>{{static_cast<T*>(mapping.get()), entry->count}, std::move(mapping)};
  }
  // In the parent, after ReadInChildProcess returned true: the array the child stored under
  // `name` as values of T, or nothing when it stored none such.
  template <typename T>
  [[nodiscard]] std::optional<std::vector<T>> Take(const std::string& name) {
    const Entry* entry = Find(name, sizeof(T));
    if (entry == nullptr) return std::nullopt;
    std::vector<T> values;
    if (entry->in_file != 0) {
      const std::shared_ptr<void> mapping = Map(*entry);
      const T* first = static_cast<const T*>(mapping.get());
      values.assign(first, first + entry->count);
      return values;
    }
    values.reserve(entry->count);
    MoveOut(*entry, [&](const void* data, std::size_t count) {
      const T* first = static_cast<const T*>(data);
      values.insert(values.end(), first, first + count);
    });
    return values;
  }

 private:
  friend bool ReadInChildProcess(const std::filesystem::path&, SharedArrays&,
                                 const std::function<void(SharedArrays&)>&, double);
  static constexpr std::uint32_t kMaxArrays = 8;
  struct Entry {
    char name[32] = {};
    std::uint32_t value_bytes = 0;
    std::uint32_t in_file = 0;  // 1: `offset` is in the file read, not in the memory file
    std::uint64_t offset = 0;
    std::uint64_t count = 0;
  };
  // The file as the child found it, so that the parent maps the same file's pages.
  struct FileIdentity {
    std::uint64_t device = 0, inode = 0, bytes = 0;
    std::int64_t modified_ns = 0;
    bool operator==(const FileIdentity&) const = default;
  };
  struct Directory {
    std::uint32_t magic = 0;
    std::uint32_t complete = 0;
    std::uint32_t arrays = 0;
    Entry entries[kMaxArrays];
    FileIdentity file;
  };
  [[nodiscard]] static std::optional<FileIdentity> IdentityOf(int fd);  // nothing when fd < 0
  Entry& AddEntry(const std::string& name, std::size_t count, std::size_t value_bytes);
  void* Allocate(const std::string& name, std::size_t count, std::size_t value_bytes);
  void LeaveInFile(const std::string& name, const FileExtent& extent, std::size_t value_bytes);
  [[nodiscard]] std::shared_ptr<void> MapFile(const Entry& entry) const;
  void MarkComplete();
  [[nodiscard]] bool ReadDirectory();
  [[nodiscard]] const Entry* Find(const std::string& name, std::size_t value_bytes) const;
  void MoveOut(const Entry& entry, const std::function<void(const void*, std::size_t)>& append);
  [[nodiscard]] std::shared_ptr<void> Map(const Entry& entry) const;

  int fd_ = -1;
  std::filesystem::path path_;  // of the file read (set by ReadInChildProcess)
  std::size_t end_ = 4096;      // the directory's page comes first
  Directory directory_;
  std::vector<std::pair<void*, std::size_t>> mappings_;  // the child's
};

// As ReadFirstInChildProcess, with the same refusals, but the child's `read` stores what it read
// in `arrays` for the parent to take: the file's data are read once. True when the child read the
// file and its arrays are there to take (the caller then reads only the file's header itself);
// false when no child could be started, or the reader refused the file in the child: the caller
// then reads the whole file itself, and a refusal comes again with the reader's own message.
bool ReadInChildProcess(const std::filesystem::path& path, SharedArrays& arrays,
                        const std::function<void(SharedArrays&)>& read, double timeout_s = 0.0);

class File {
 public:
  // Opens read-only. Throws Error{kBadInput} if the file is not HDF5 or is damaged.
  static File OpenReadOnly(const std::filesystem::path& path);
  // Opens a file image held in memory (the bytes are copied); `name` stands for it in messages.
  static File OpenImage(const void* data, size_t size, const std::string& name);
  // Creates (truncating) for writing. Throws Error{kIo}.
  static File Create(const std::filesystem::path& path);

  [[nodiscard]] bool HasObject(const std::string& name) const;
  void CreateGroup(const std::string& name);

  // Dataset shape; empty for a scalar.
  [[nodiscard]] std::vector<hsize_t> Shape(const std::string& dataset) const;
  // Class and size in bytes of the stored element type.
  [[nodiscard]] H5T_class_t ElementClass(const std::string& dataset) const;
  [[nodiscard]] size_t ElementSize(const std::string& dataset) const;
  // Reads any numeric dataset converted to double (HDF5 converts in place, no second copy).
  [[nodiscard]] std::vector<double> ReadDoubles(const std::string& dataset) const;
  // Reads a numeric dataset as float (for float32 data that need no widening).
  [[nodiscard]] std::vector<float> ReadFloats(const std::string& dataset) const;
  // The number of values of a numeric dataset; Error{kBadInput} when it is not numeric, or declares
  // more values (of `value_bytes` each in memory) than the file could hold, so that a damaged
  // header is refused before anything is allocated for it.
  [[nodiscard]] std::size_t NumericCount(const std::string& dataset, std::size_t value_bytes) const;
  // Where the values of `dataset` lie in the file when they can be used as they are stored: one
  // dimension, contiguous (so unfiltered), little-endian IEEE float32 on this little-endian
  // machine, aligned for float, inside the file, and what libhdf5 reads at both ends; nothing
  // otherwise (chunked, compressed, external, not yet written, other types, a file in memory).
  [[nodiscard]] std::optional<FileExtent> ContiguousFloat32Extent(const std::string& dataset) const;
  // Reads a numeric dataset into `values`, which must hold NumericCount values (converted by HDF5).
  void ReadInto(const std::string& dataset, std::span<double> values) const;
  void ReadInto(const std::string& dataset, std::span<float> values) const;
  void WriteDoubles(const std::string& dataset, const std::vector<double>& values,
                    const std::vector<hsize_t>& shape);
  void WriteFloats(const std::string& dataset, const std::vector<float>& values,
                   const std::vector<hsize_t>& shape);
  void WriteInts(const std::string& dataset, const std::vector<int>& values,
                 const std::vector<hsize_t>& shape);

  // Attributes on an object ("/" or a group or dataset path).
  [[nodiscard]] bool HasAttribute(const std::string& object, const std::string& name) const;
  [[nodiscard]] std::optional<double> ReadAttributeDouble(const std::string& object,
                                                          const std::string& name) const;
  // Text stored in any way HDF5 allows (variable or fixed length, ASCII or UTF-8, null-terminated,
  // null- or space-padded, scalar or one-element array), byte-exact; a number as its shortest form.
  [[nodiscard]] std::optional<std::string> ReadAttributeString(const std::string& object,
                                                               const std::string& name) const;
  // The names of the attributes on `object`, in creation order where the file tracks it.
  [[nodiscard]] std::vector<std::string> AttributeNames(const std::string& object) const;
  // The first element of a compound attribute (e.g. Zygo's `Z Converter`): its string members
  // (fixed or variable length) and numeric members (a number, a fixed array or a variable-length
  // sequence, converted to double) by member name; other member kinds are left out.
  struct Compound {
    std::map<std::string, std::string> strings;
    std::map<std::string, std::vector<double>> numbers;
  };
  [[nodiscard]] std::optional<Compound> ReadAttributeCompound(const std::string& object,
                                                              const std::string& name) const;
  // The string columns `columns` of a one-dimensional compound dataset, row by row (e.g. the
  // /MetaData table of a Zygo .datx: Source, Link, Destination); each column a fixed or
  // variable-length string. Throws Error{kBadInput} naming the dataset if it is not such a table,
  // lacks a column, or holds more than 65536 rows.
  [[nodiscard]] std::vector<std::vector<std::string>> ReadStringTable(
      const std::string& dataset, const std::vector<std::string>& columns) const;
  // The names of the datasets directly in `group`, in name order; empty if there is no such group.
  // Throws Error{kBadInput} if the group cannot be listed or holds more than 65536 members.
  [[nodiscard]] std::vector<std::string> DatasetNames(const std::string& group) const;
  void WriteAttribute(const std::string& object, const std::string& name, double value);
  void WriteAttribute(const std::string& object, const std::string& name, const std::string& value);

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  File(Handle handle, std::filesystem::path path) : handle_(std::move(handle)), path_(std::move(path)) {}
  [[nodiscard]] Handle OpenDataset(const std::string& dataset) const;
  // Attribute `name` of `object`, which the caller has checked exists.
  [[nodiscard]] Handle OpenAttribute(const std::string& object, const std::string& name) const;
  [[nodiscard]] std::string Where(const std::string& object) const;
  // "attribute 'name' on <Where(object)>", for messages.
  [[nodiscard]] std::string AttributeWhere(const std::string& object, const std::string& name) const;
  // Before libhdf5 reads a variable-length attribute or dataset (or `member` of a compound one) of
  // `stored_type`: throws Error{kBadInput} unless every global heap object it refers to is one the
  // library can read safely (see hdf5_heap.cc).
  void CheckHeapReferences(hid_t object, hid_t stored_type, const std::string& what,
                           const char* member = nullptr) const;
  // `size` bytes at `address` (relative to the HDF5 base address); shorter at the end of the file.
  [[nodiscard]] std::string ReadRawBytes(uint64_t address, uint64_t size) const;

  Handle handle_;
  std::filesystem::path path_;
  std::shared_ptr<const std::string> image_;  // the bytes of a file opened from memory
};

}  // namespace arcwheel::hdf5
