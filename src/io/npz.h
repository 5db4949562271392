#pragma once
// NumPy .npz archives, written and read without NumPy (docs/result-format.md, "npz"): a ZIP archive
// (stored, uncompressed members; ZIP64 records throughout, so that members and archives over
// 4 GiB work) of .npy arrays (format 1.0: a dict header with descr, fortran_order and shape,
// padded so that the data starts 64-byte aligned in the member). Private to the library and its
// tests.

#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "io/atomic_file.h"

namespace flexkin {

// The .npy header of an array of `descr` ("<f8", "<i8") in C order with `shape`, padded with
// spaces to `length` bytes (0: the smallest multiple of 64 that holds it).
std::string NpyHeader(const std::string& descr, const std::vector<uint64_t>& shape,
                      size_t length = 0);

// Writes the members of a ZIP archive one after another into `file`: each member's data streams
// through Write, its CRC-32 computed on the way; its local header's sizes and CRC are patched when
// it ends. A member may start with a provisional prefix (an .npy header whose shape is not known
// yet) that EndMember replaces by one of the same length.
class ZipWriter {
 public:
  explicit ZipWriter(AtomicFile* file) : file_(file) {}
  void BeginMember(const std::string& name, const std::string& prefix = "");
  void Write(const void* data, size_t size);
  // Ends the member; `final_prefix` replaces the prefix given to BeginMember (same length; ""
  // keeps it).
  void EndMember(const std::string& final_prefix = "");
  // A whole member at once.
  void AddMember(const std::string& name, const std::string& data);
  // The central directory and the end records. The archive is complete after this.
  void Finish();
  // Bytes of the current member written so far, prefix included.
  uint64_t member_size() const { return size_; }

 private:
  struct Entry {
    std::string name;
    uint64_t offset = 0, size = 0;
    uint32_t crc = 0;
  };
  AtomicFile* file_;
  std::vector<Entry> entries_;
  bool open_ = false;
  std::string prefix_;
  uint64_t offset_ = 0, size_ = 0;
  unsigned long body_crc_ = 0;
};

// A ZIP archive read member by member (stored members only). Every structure is checked against
// the file's size before it is used: a malformed archive throws InputError naming the structure
// ("zip: end of central directory") or the member ("frames.npy"), never reads out of bounds.
// Opening the archive checks every member that the central directory lists: its local header
// against its central directory entry, its bytes (local header and data) against every other
// member's and the central directory's, and, for a member the caller does not read itself, its
// data against its CRC-32 (the other members' data is checked by Member::Finish when read).
class ZipReader {
 public:
  // The members that flexkin's readers of .npz files (ReadResultFile, StrandFileReader) read
  // through Member or ReadWhole: the default of `read_later`.
  static const std::set<std::string>& LibraryMembers();

  // Throws std::system_error if the file cannot be read, InputError if it is not a valid archive.
  // The data of every member not named in `read_later` is read and its CRC-32 checked here.
  explicit ZipReader(const std::string& path,
                     const std::set<std::string>& read_later = LibraryMembers());
  ~ZipReader();
  ZipReader(const ZipReader&) = delete;
  ZipReader& operator=(const ZipReader&) = delete;

  bool Has(const std::string& name) const { return members_.count(name) > 0; }

  // Reads a member sequentially: Read fills exactly `size` bytes (InputError if the member ends
  // first); Finish checks that the member was read whole and that its CRC-32 matches.
  class Member {
   public:
    Member(const ZipReader* zip, const std::string& name);
    uint64_t size() const { return size_; }
    uint64_t left() const { return size_ - consumed_; }
    void Read(void* out, size_t size);
    void Finish();

   private:
    const ZipReader* zip_;
    std::string name_;
    uint64_t start_ = 0, size_ = 0, loaded_ = 0, consumed_ = 0;
    uint32_t expected_crc_ = 0;
    unsigned long crc_ = 0;
    std::vector<char> buffer_;
    size_t buffer_pos_ = 0;
  };

  // A whole member, at most `max_size` bytes.
  std::string ReadWhole(const std::string& name, uint64_t max_size);

 private:
  struct Entry {
    uint64_t local_offset = 0, data_offset = 0, size = 0;
    uint32_t crc = 0;
  };
  // A member's name and the field that names it in messages (printable, or the central
  // directory entry of an empty name).
  struct Named {
    std::string name, field;
    uint64_t flags = 0, method = 0;  // of its central directory entry
  };
  void ReadAt(uint64_t offset, void* out, size_t size, const std::string& what) const;
  // Reads the fixed part of a member's local header (its signature, the lengths of its name and
  // extra field), sets e->data_offset and checks that the header and the data end before the
  // central directory.
  void PlaceMember(const std::string& field, Entry* e) const;
  // Reads the whole local header and checks it against the central directory entry: name,
  // flags (bits 0 and 3), compression method, CRC-32 and sizes.
  void CheckLocalHeader(const Named& m, const Entry& e) const;
  // Refuses members whose bytes overlap; `order`: the members in central directory order.
  void CheckNoOverlap(const std::vector<Named>& order) const;
  // Reads a member's whole data and checks its CRC-32.
  void CheckCrc(const std::string& field, const Entry& e) const;
  int fd_ = -1;
  std::string path_;
  uint64_t file_size_ = 0, members_end_ = 0;  // members lie in [0, members_end_)
  uint64_t cd_size_ = 0;                      // the central directory follows, at members_end_
  std::map<std::string, Entry> members_;
};

// An .npy member's header, read and checked: descr, fortran_order False, shape.
struct NpyArray {
  std::string descr;
  std::vector<uint64_t> shape;
  uint64_t count = 0;  // product of shape
};
// Reads the header of the .npy member being read by `member` (left at the first data byte) and
// checks that descr is `descr` ("<f8", "<i8", "<f4" or "|b1") and that the member holds exactly
// count items of that size after the header. InputError named `name`.
NpyArray ReadNpyHeader(ZipReader::Member* member, const std::string& name,
                       const std::string& descr);
// Throws InputError (`name`: "has shape (2, 3); expected (4, 3); not <file_kind>") unless the
// array has `shape`.
void ExpectNpyShape(const NpyArray& a, const std::string& name, const std::vector<uint64_t>& shape,
                    const std::string& file_kind);

}  // namespace flexkin
