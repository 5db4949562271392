// NumPy .npz archives: ZIP (with ZIP64 records) of .npy arrays, written and read here
// (src/io/npz.h). The ZIP structures are those of PKWARE's APPNOTE (sections 4.3 and 4.5); the
// .npy header is NumPy's format 1.0.
#include "io/npz.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>
#include <ostream>
#include <stdexcept>
#include <system_error>

#include "flexkin/error.h"

namespace flexkin {
namespace {

static_assert(sizeof(z_off_t) >= 8, "crc32_combine needs 64-bit offsets");

constexpr uint32_t kLocalHeaderSignature = 0x04034b50;
constexpr uint32_t kCentralHeaderSignature = 0x02014b50;
constexpr uint32_t kZip64EndSignature = 0x06064b50;
constexpr uint32_t kZip64LocatorSignature = 0x07064b50;
constexpr uint32_t kEndSignature = 0x06054b50;
constexpr uint16_t kVersion = 45;  // ZIP64
constexpr uint16_t kZip64ExtraId = 0x0001;
constexpr uint16_t kDosDate = (0 << 9) | (1 << 5) | 1;  // 1980-01-01: reproducible archives
constexpr size_t kLocalHeaderSize = 30, kCentralHeaderSize = 46, kEndSize = 22;
constexpr size_t kZip64EndSize = 56, kZip64LocatorSize = 20;
constexpr char kNpyMagic[] = "\x93NUMPY";

void Put16(std::string* out, uint16_t v) {
  for (int i = 0; i < 2; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void Put32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void Put64(std::string* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
uint64_t Get(const unsigned char* p, int bytes) {
  uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
uint32_t Crc(unsigned long crc, const void* data, size_t size) {
  const Bytef* p = static_cast<const Bytef*>(data);
  while (size > 0) {  // crc32 takes a uInt length
    const uInt n = static_cast<uInt>(std::min<size_t>(size, 1u << 30));
    crc = ::crc32(crc, p, n);
    p += n;
    size -= n;
  }
  return static_cast<uint32_t>(crc);
}
uint16_t Cap16(uint64_t v) { return v >= 0xffff ? 0xffff : static_cast<uint16_t>(v); }
uint32_t Cap32(uint64_t v) { return v >= 0xffffffffu ? 0xffffffffu : static_cast<uint32_t>(v); }

// The local header of a member whose sizes and CRC are patched at its end: ZIP64 sizes in the
// extra field, 0xffffffff in the fixed fields.
std::string LocalHeader(const std::string& name, uint32_t crc, uint64_t size) {
  std::string h;
  Put32(&h, kLocalHeaderSignature);
  Put16(&h, kVersion);
  Put16(&h, 0);  // flags
  Put16(&h, 0);  // stored
  Put16(&h, 0);  // time
  Put16(&h, kDosDate);
  Put32(&h, crc);
  Put32(&h, 0xffffffffu);
  Put32(&h, 0xffffffffu);
  Put16(&h, static_cast<uint16_t>(name.size()));
  Put16(&h, 20);
  h += name;
  Put16(&h, kZip64ExtraId);
  Put16(&h, 16);
  Put64(&h, size);  // uncompressed
  Put64(&h, size);  // compressed
  return h;
}

[[noreturn]] void Malformed(const std::string& field, const std::string& message) {
  throw InputError(field, message + "; not a valid .npz result file");
}

// A member's name from the file as the field of a message: bytes outside printable ASCII as \xNN
// (a NUL would cut what() short, a control character garble a terminal), at most 64 bytes of it.
std::string PrintableName(const std::string& name) {
  constexpr size_t kShown = 64;
  std::string out;
  for (size_t i = 0; i < std::min(name.size(), kShown); ++i) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      out += static_cast<char>(c);
    } else {
      static const char kHex[] = "0123456789abcdef";
      out += {'\\', 'x', kHex[c >> 4], kHex[c & 15]};
    }
  }
  if (name.size() > kShown) out += "...";
  return out;
}

std::string Hex(uint64_t v, int digits) {
  static const char kHex[] = "0123456789abcdef";
  std::string out = "0x";
  for (int i = digits - 1; i >= 0; --i) out += kHex[(v >> (4 * i)) & 15];
  return out;
}

// "N bytes at offsets A to B": the half-open range [A, B) of a message.
std::string Range(uint64_t start, uint64_t end) {
  return std::to_string(end - start) + " bytes at offsets " + std::to_string(start) + " to " +
         std::to_string(end);
}

// The flags that a local header and its central directory entry must agree on: bit 0 (encrypted)
// and bit 3 (sizes and CRC-32 in a data descriptor after the data).
constexpr uint64_t kComparedFlags = 0x0009;

}  // namespace

std::string NpyHeader(const std::string& descr, const std::vector<uint64_t>& shape, size_t length) {
  std::string dict = "{'descr': '" + descr + "', 'fortran_order': False, 'shape': (";
  for (size_t i = 0; i < shape.size(); ++i) {
    dict += std::to_string(shape[i]) + (shape.size() == 1 ? "," : i + 1 < shape.size() ? ", " : "");
  }
  dict += "), }";
  // magic (6), version (2), header length (2), the dict, spaces, '\n'.
  const size_t minimum = 10 + dict.size() + 1;
  if (length == 0) length = (minimum + 63) / 64 * 64;
  if (length < minimum || length - 10 > 0xffff) {
    throw std::logic_error("NpyHeader: length " + std::to_string(length) + " does not fit");
  }
  std::string h(kNpyMagic, 6);
  h.push_back(1);
  h.push_back(0);
  Put16(&h, static_cast<uint16_t>(length - 10));
  h += dict;
  h.append(length - minimum, ' ');
  h.push_back('\n');
  return h;
}

void ZipWriter::BeginMember(const std::string& name, const std::string& prefix) {
  offset_ = file_->position();
  file_->stream() << LocalHeader(name, 0, 0);
  entries_.push_back({name, offset_, 0, 0});
  open_ = true;
  prefix_ = prefix;
  file_->stream() << prefix;
  size_ = prefix.size();
  body_crc_ = ::crc32(0L, Z_NULL, 0);
}

void ZipWriter::Write(const void* data, size_t size) {
  file_->stream().write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  body_crc_ = Crc(body_crc_, data, size);
  size_ += size;
}

void ZipWriter::EndMember(const std::string& final_prefix) {
  Entry& e = entries_.back();
  const std::string& prefix = final_prefix.empty() ? prefix_ : final_prefix;
  if (prefix.size() != prefix_.size()) throw std::logic_error("ZipWriter: prefix length changed");
  const uint64_t body = size_ - prefix.size();
  e.size = size_;
  e.crc = static_cast<uint32_t>(
      ::crc32_combine(Crc(::crc32(0L, Z_NULL, 0), prefix.data(), prefix.size()), body_crc_,
                      static_cast<z_off_t>(body)));
  file_->Check();
  file_->WriteAt(e.offset, LocalHeader(e.name, e.crc, e.size).data(),
                 kLocalHeaderSize + e.name.size() + 20);
  if (!final_prefix.empty()) {
    file_->WriteAt(e.offset + kLocalHeaderSize + e.name.size() + 20, prefix.data(), prefix.size());
  }
  open_ = false;
}

void ZipWriter::AddMember(const std::string& name, const std::string& data) {
  BeginMember(name);
  Write(data.data(), data.size());
  EndMember();
}

void ZipWriter::Finish() {
  std::ostream& out = file_->stream();
  const uint64_t cd_offset = file_->position();
  for (const Entry& e : entries_) {
    std::string h;
    Put32(&h, kCentralHeaderSignature);
    Put16(&h, kVersion);  // made by
    Put16(&h, kVersion);  // needed
    Put16(&h, 0);
    Put16(&h, 0);
    Put16(&h, 0);
    Put16(&h, kDosDate);
    Put32(&h, e.crc);
    Put32(&h, 0xffffffffu);
    Put32(&h, 0xffffffffu);
    Put16(&h, static_cast<uint16_t>(e.name.size()));
    Put16(&h, 28);  // the ZIP64 extra field
    Put16(&h, 0);   // comment
    Put16(&h, 0);   // disk
    Put16(&h, 0);   // internal attributes
    Put32(&h, 0);   // external attributes
    Put32(&h, 0xffffffffu);
    h += e.name;
    Put16(&h, kZip64ExtraId);
    Put16(&h, 24);
    Put64(&h, e.size);
    Put64(&h, e.size);
    Put64(&h, e.offset);
    out << h;
  }
  const uint64_t zip64_end = file_->position();
  const uint64_t cd_size = zip64_end - cd_offset;
  std::string t;
  Put32(&t, kZip64EndSignature);
  Put64(&t, kZip64EndSize - 12);
  Put16(&t, kVersion);
  Put16(&t, kVersion);
  Put32(&t, 0);
  Put32(&t, 0);
  Put64(&t, entries_.size());
  Put64(&t, entries_.size());
  Put64(&t, cd_size);
  Put64(&t, cd_offset);
  Put32(&t, kZip64LocatorSignature);
  Put32(&t, 0);
  Put64(&t, zip64_end);
  Put32(&t, 1);
  Put32(&t, kEndSignature);
  Put16(&t, 0);
  Put16(&t, 0);
  Put16(&t, Cap16(entries_.size()));
  Put16(&t, Cap16(entries_.size()));
  Put32(&t, Cap32(cd_size));
  Put32(&t, Cap32(cd_offset));
  Put16(&t, 0);
  out << t;
  file_->Check();
}

const std::set<std::string>& ZipReader::LibraryMembers() {
  static const std::set<std::string> names = {
      // a result (io/result_npz.cc)
      "result.json", "link_lengths.npy", "path_length.npy", "l2_per_step.npy",
      "l2_weighted_per_step.npy", "frames.npy", "steps.npy", "link_angles.npy",
      // a strand file (io/strand_file.cc)
      "groom.json", "offsets.npy", "times.npy", "body_rotation.npy", "body_translation.npy",
      "points.npy"};
  return names;
}

ZipReader::ZipReader(const std::string& path, const std::set<std::string>& read_later)
    : path_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) {
    throw std::system_error(errno, std::generic_category(), "cannot read '" + path + "'");
  }
  struct stat st;
  if (::fstat(fd_, &st) != 0) {
    const int err = errno;
    ::close(fd_);
    throw std::system_error(err, std::generic_category(), "cannot read '" + path + "'");
  }
  // The destructor does not run when the constructor throws: a malformed archive closes the file
  // here (each refused file used to keep a descriptor open).
  struct CloseUnlessKept {
    int* fd;
    bool keep = false;
    ~CloseUnlessKept() {
      if (!keep) {
        ::close(*fd);
        *fd = -1;
      }
    }
  } closer{&fd_};
  file_size_ = static_cast<uint64_t>(st.st_size);
  const std::string end_field = "zip: end of central directory";
  if (file_size_ < kEndSize) Malformed(end_field, "is missing (the file is too short)");
  // The end record: the last signature whose comment reaches exactly to the end of the file.
  const uint64_t tail_size = std::min<uint64_t>(file_size_, kEndSize + 0xffff);
  std::vector<unsigned char> tail(tail_size);
  ReadAt(file_size_ - tail_size, tail.data(), tail.size(), end_field);
  uint64_t end_pos = 0;
  bool found = false;
  for (uint64_t i = tail_size - kEndSize + 1; i-- > 0;) {
    const unsigned char* p = tail.data() + i;
    if (Get(p, 4) == kEndSignature && i + kEndSize + Get(p + 20, 2) == tail_size) {
      end_pos = file_size_ - tail_size + i;
      found = true;
      break;
    }
  }
  if (!found) Malformed(end_field, "is missing (the file is truncated or not a ZIP archive)");
  const unsigned char* end = tail.data() + (end_pos - (file_size_ - tail_size));
  uint64_t entries = Get(end + 10, 2), cd_size = Get(end + 12, 4), cd_offset = Get(end + 16, 4);
  if (Get(end + 4, 2) != 0 || Get(end + 6, 2) != 0 || Get(end + 8, 2) != entries) {
    Malformed(end_field, "describes a multi-disk archive");
  }
  members_end_ = end_pos;
  // ZIP64: a locator right before the end record points at the ZIP64 end record.
  if (end_pos >= kZip64LocatorSize) {
    unsigned char loc[kZip64LocatorSize];
    ReadAt(end_pos - kZip64LocatorSize, loc, sizeof loc, "zip: ZIP64 end locator");
    if (Get(loc, 4) == kZip64LocatorSignature) {
      const uint64_t z = Get(loc + 8, 8);
      const std::string field = "zip: ZIP64 end of central directory";
      if (z > end_pos - kZip64LocatorSize || end_pos - kZip64LocatorSize - z < kZip64EndSize) {
        Malformed(field, "offset " + std::to_string(z) + " is outside the file");
      }
      unsigned char rec[kZip64EndSize];
      ReadAt(z, rec, sizeof rec, field);
      if (Get(rec, 4) != kZip64EndSignature) Malformed(field, "has a bad signature");
      if (Get(rec + 16, 4) != 0 || Get(rec + 20, 4) != 0 || Get(rec + 24, 8) != Get(rec + 32, 8)) {
        Malformed(field, "describes a multi-disk archive");
      }
      entries = Get(rec + 32, 8);
      cd_size = Get(rec + 40, 8);
      cd_offset = Get(rec + 48, 8);
      members_end_ = z;
    }
  }
  const std::string cd_field = "zip: central directory";
  if (cd_offset > members_end_ || cd_size > members_end_ - cd_offset) {
    Malformed(cd_field, "(offset " + std::to_string(cd_offset) + ", " + std::to_string(cd_size) +
                            " bytes) lies outside the file");
  }
  if (cd_size > (16u << 20) || entries > cd_size / kCentralHeaderSize) {
    Malformed(cd_field, "has " + std::to_string(entries) + " entries in " +
                            std::to_string(cd_size) + " bytes");
  }
  std::vector<unsigned char> cd(cd_size);
  ReadAt(cd_offset, cd.data(), cd.size(), cd_field);
  members_end_ = cd_offset;
  cd_size_ = cd_size;
  std::vector<Named> order;  // the members in central directory order
  size_t pos = 0;
  for (uint64_t k = 0; k < entries; ++k) {
    const std::string field = cd_field + " entry " + std::to_string(k);
    if (cd.size() - pos < kCentralHeaderSize) Malformed(field, "is truncated");
    const unsigned char* p = cd.data() + pos;
    if (Get(p, 4) != kCentralHeaderSignature) Malformed(field, "has a bad signature");
    const uint64_t flags = Get(p + 8, 2), method = Get(p + 10, 2);
    Entry e;
    e.crc = static_cast<uint32_t>(Get(p + 16, 4));
    uint64_t compressed = Get(p + 20, 4), size = Get(p + 24, 4);
    const size_t name_len = Get(p + 28, 2), extra_len = Get(p + 30, 2),
                 comment_len = Get(p + 32, 2);
    e.local_offset = Get(p + 42, 4);
    if (cd.size() - pos - kCentralHeaderSize < name_len + extra_len + comment_len) {
      Malformed(field, "is truncated");
    }
    const std::string name(reinterpret_cast<const char*>(p + kCentralHeaderSize), name_len);
    const std::string member_field = name.empty() ? field : PrintableName(name);
    // The ZIP64 extra field holds the values whose fixed fields are 0xffffffff, in this order.
    const unsigned char* x = p + kCentralHeaderSize + name_len;
    size_t x_left = extra_len;
    while (x_left >= 4) {
      const uint64_t id = Get(x, 2), len = Get(x + 2, 2);
      if (len > x_left - 4) Malformed(member_field, "ZIP extra field is truncated");
      if (id == kZip64ExtraId) {
        const unsigned char* v = x + 4;
        uint64_t v_left = len;
        for (uint64_t* field_value : {&size, &compressed, &e.local_offset}) {
          if (*field_value != 0xffffffffu) continue;
          if (v_left < 8) Malformed(member_field, "ZIP64 extra field is truncated");
          *field_value = Get(v, 8);
          v += 8;
          v_left -= 8;
        }
      }
      x += 4 + len;
      x_left -= 4 + len;
    }
    if (flags & 1) Malformed(member_field, "is encrypted");
    if (method != 0 || compressed != size) {
      Malformed(member_field,
                "is compressed (method " + std::to_string(method) +
                    "); expected a stored member (numpy.savez, not savez_compressed)");
    }
    e.size = size;
    if (e.local_offset > members_end_ || members_end_ - e.local_offset < kLocalHeaderSize) {
      Malformed(member_field, "local header offset " + std::to_string(e.local_offset) +
                                  " lies outside the members");
    }
    if (members_.count(name) > 0) Malformed(member_field, "appears twice");
    PlaceMember(member_field, &e);
    members_.emplace(name, e);
    order.push_back({name, member_field, flags, method});
    pos += kCentralHeaderSize + name_len + extra_len + comment_len;
  }
  // Before the local headers' names and extra fields are read: with no two members sharing
  // bytes, what is read below is at most the file.
  CheckNoOverlap(order);
  for (const Named& m : order) CheckLocalHeader(m, members_.at(m.name));
  for (const Named& m : order) {
    if (read_later.count(m.name) == 0) CheckCrc(m.field, members_.at(m.name));
  }
  closer.keep = true;
}

void ZipReader::PlaceMember(const std::string& field, Entry* e) const {
  unsigned char h[kLocalHeaderSize];
  ReadAt(e->local_offset, h, sizeof h, field + " local header");
  if (Get(h, 4) != kLocalHeaderSignature) {
    Malformed(field, "local header at offset " + std::to_string(e->local_offset) +
                         " has signature " + Hex(Get(h, 4), 8) + "; expected " +
                         Hex(kLocalHeaderSignature, 8));
  }
  const uint64_t variable = Get(h + 26, 2) + Get(h + 28, 2);  // name and extra field
  const std::string cd_range = Range(members_end_, members_end_ + cd_size_);
  // The central directory entry's check leaves at least the fixed part before members_end_.
  if (variable > members_end_ - e->local_offset - kLocalHeaderSize) {
    Malformed(field, "local header (" +
                         Range(e->local_offset, e->local_offset + kLocalHeaderSize + variable) +
                         ") overlaps the central directory (" + cd_range + ")");
  }
  e->data_offset = e->local_offset + kLocalHeaderSize + variable;
  if (e->size > members_end_ - e->data_offset) {
    Malformed(field, "data (" + Range(e->data_offset, e->data_offset + e->size) +
                         ") overlaps the central directory (" + cd_range + ")");
  }
}

void ZipReader::CheckLocalHeader(const Named& m, const Entry& e) const {
  const std::string& field = m.field;
  const std::string cd = " as in the central directory";
  std::vector<unsigned char> h(e.data_offset - e.local_offset);
  ReadAt(e.local_offset, h.data(), h.size(), field + " local header");
  const uint64_t name_len = Get(h.data() + 26, 2), extra_len = Get(h.data() + 28, 2);
  const std::string local_name(reinterpret_cast<const char*>(h.data()) + kLocalHeaderSize,
                               name_len);
  if (local_name != m.name) {
    Malformed(field, "local header names \"" + PrintableName(local_name) + "\"; expected \"" +
                         PrintableName(m.name) + "\"" + cd);
  }
  const uint64_t flags = Get(h.data() + 6, 2), method = Get(h.data() + 8, 2);
  if ((flags & kComparedFlags) != (m.flags & kComparedFlags)) {
    Malformed(field, "local header flags " + Hex(flags, 4) + " (bits 0, encrypted, and 3, " +
                         "data descriptor); expected " + Hex(m.flags & kComparedFlags, 4) +
                         " in those bits" + cd);
  }
  if (method != m.method) {
    Malformed(field, "local header compression method " + std::to_string(method) + "; expected " +
                         std::to_string(m.method) + cd);
  }
  // Sizes: the fixed fields, or where they are 0xffffffff the ZIP64 extra field's values, in
  // the order uncompressed, compressed.
  uint64_t size = Get(h.data() + 22, 4), compressed = Get(h.data() + 18, 4);
  const unsigned char* x = h.data() + kLocalHeaderSize + name_len;
  uint64_t x_left = extra_len;
  while (x_left >= 4) {
    const uint64_t id = Get(x, 2), len = Get(x + 2, 2);
    if (len > x_left - 4) Malformed(field, "local header's ZIP extra field is truncated");
    if (id == kZip64ExtraId) {
      const unsigned char* value = x + 4;
      uint64_t value_left = len;
      for (uint64_t* field_value : {&size, &compressed}) {
        if (*field_value != 0xffffffffu) continue;
        if (value_left < 8) Malformed(field, "local header's ZIP64 extra field is truncated");
        *field_value = Get(value, 8);
        value += 8;
        value_left -= 8;
      }
    }
    x += 4 + len;
    x_left -= 4 + len;
  }
  // With a data descriptor (flag bit 3) the local header may hold 0 for the CRC-32 and sizes.
  const bool descriptor = (flags & 8) != 0;
  const uint64_t crc = Get(h.data() + 14, 4);
  if (crc != e.crc && !(descriptor && crc == 0)) {
    Malformed(field, "local header CRC-32 " + Hex(crc, 8) + "; expected " + Hex(e.crc, 8) + cd);
  }
  for (const auto& [value, what] : {std::pair{size, "uncompressed"}, {compressed, "compressed"}}) {
    if (value != e.size && !(descriptor && value == 0)) {
      Malformed(field, std::string("local header ") + what + " size " + std::to_string(value) +
                           "; expected " + std::to_string(e.size) + cd);
    }
  }
}

void ZipReader::CheckNoOverlap(const std::vector<Named>& order) const {
  struct Span {
    uint64_t start, end;
    const std::string* field;
  };
  std::vector<Span> spans;
  spans.reserve(order.size());
  for (const Named& m : order) {
    const Entry& e = members_.at(m.name);
    spans.push_back({e.local_offset, e.data_offset + e.size, &m.field});
  }
  // By start, then central directory order; each span against the one reaching furthest so far.
  std::stable_sort(spans.begin(), spans.end(),
                   [](const Span& a, const Span& b) { return a.start < b.start; });
  const Span* furthest = nullptr;
  for (const Span& s : spans) {
    if (furthest != nullptr && s.start < furthest->end) {
      Malformed(*s.field, "local header and data (" + Range(s.start, s.end) +
                              ") overlap those of \"" + *furthest->field + "\" (" +
                              Range(furthest->start, furthest->end) + "); expected members apart");
    }
    if (furthest == nullptr || s.end > furthest->end) furthest = &s;
  }
}

void ZipReader::CheckCrc(const std::string& field, const Entry& e) const {
  std::vector<char> chunk(static_cast<size_t>(std::min<uint64_t>(e.size, 1u << 20)));
  unsigned long crc = ::crc32(0L, Z_NULL, 0);
  for (uint64_t done = 0; done < e.size;) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(e.size - done, chunk.size()));
    ReadAt(e.data_offset + done, chunk.data(), n, field);
    crc = Crc(crc, chunk.data(), n);
    done += n;
  }
  if (static_cast<uint32_t>(crc) != e.crc) {
    Malformed(field, "CRC-32 of its data is " + Hex(static_cast<uint32_t>(crc), 8) + "; expected " +
                         Hex(e.crc, 8) + " as in the central directory (the member is corrupted)");
  }
}

ZipReader::~ZipReader() {
  if (fd_ >= 0) ::close(fd_);
}

void ZipReader::ReadAt(uint64_t offset, void* out, size_t size, const std::string& what) const {
  if (offset > file_size_ || size > file_size_ - offset) {
    Malformed(what, "lies outside the file");
  }
  char* p = static_cast<char*>(out);
  while (size > 0) {
    const ssize_t n = ::pread(fd_, p, size, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0)
      throw std::system_error(errno, std::generic_category(), "cannot read '" + path_ + "'");
    if (n == 0) Malformed(what, "lies outside the file (it changed while read)");
    p += n;
    offset += static_cast<uint64_t>(n);
    size -= static_cast<size_t>(n);
  }
}

ZipReader::Member::Member(const ZipReader* zip, const std::string& name) : zip_(zip), name_(name) {
  const auto it = zip->members_.find(name);
  if (it == zip->members_.end()) Malformed(name, "is missing from the archive");
  // The local header and the data's place were checked when the archive was opened.
  const Entry& e = it->second;
  start_ = e.data_offset;
  size_ = e.size;
  expected_crc_ = e.crc;
  crc_ = ::crc32(0L, Z_NULL, 0);
}

void ZipReader::Member::Read(void* out, size_t size) {
  if (size > left()) {
    Malformed(name_, "ends after " + std::to_string(size_) + " bytes; expected at least " +
                         std::to_string(consumed_ + size));
  }
  char* p = static_cast<char*>(out);
  consumed_ += size;
  while (size > 0) {
    if (buffer_pos_ == buffer_.size()) {  // refill: up to 1 MiB of what is left
      const size_t n = static_cast<size_t>(std::min<uint64_t>(size_ - loaded_, 1u << 20));
      buffer_.resize(n);
      zip_->ReadAt(start_ + loaded_, buffer_.data(), n, name_);
      crc_ = Crc(crc_, buffer_.data(), n);
      buffer_pos_ = 0;
      loaded_ += n;
    }
    const size_t n = std::min(size, buffer_.size() - buffer_pos_);
    std::memcpy(p, buffer_.data() + buffer_pos_, n);
    buffer_pos_ += n;
    p += n;
    size -= n;
  }
}

void ZipReader::Member::Finish() {
  if (left() > 0) {
    Malformed(name_, "has " + std::to_string(left()) + " bytes more than its header says");
  }
  if (static_cast<uint32_t>(crc_) != expected_crc_) {
    Malformed(name_, "CRC-32 of its data is " + Hex(static_cast<uint32_t>(crc_), 8) +
                         "; expected " + Hex(expected_crc_, 8) +
                         " as in the central directory (the member is corrupted)");
  }
}

std::string ZipReader::ReadWhole(const std::string& name, uint64_t max_size) {
  Member m(this, name);
  if (m.size() > max_size) {
    Malformed(name, "has " + std::to_string(m.size()) + " bytes; expected at most " +
                        std::to_string(max_size));
  }
  std::string data(m.size(), '\0');
  m.Read(data.data(), data.size());
  m.Finish();
  return data;
}

namespace {

// A Python literal in an .npy header: the dict's strings, booleans and tuples of integers.
class NpyDictParser {
 public:
  NpyDictParser(const std::string& text, const std::string& name) : t_(text), name_(name) {}
  void Parse(NpyArray* a, bool* fortran) {
    bool have_descr = false, have_order = false, have_shape = false;
    Expect('{');
    while (true) {
      Skip();
      if (Peek() == '}') break;
      const std::string key = String();
      Expect(':');
      if (key == "descr" && !have_descr) {
        a->descr = String();
        have_descr = true;
      } else if (key == "fortran_order" && !have_order) {
        *fortran = Bool();
        have_order = true;
      } else if (key == "shape" && !have_shape) {
        a->shape = Tuple();
        have_shape = true;
      } else {
        Fail("has an unexpected or repeated key '" + key + "'");
      }
      Skip();
      if (Peek() == ',') {
        ++pos_;
        continue;
      }
      if (Peek() != '}') Fail("expected ',' or '}'");
    }
    ++pos_;
    Skip();
    if (pos_ != t_.size()) Fail("has text after the dict");
    if (!have_descr || !have_order || !have_shape) {
      Fail("lacks one of 'descr', 'fortran_order' and 'shape'");
    }
  }

 private:
  [[noreturn]] void Fail(const std::string& what) {
    Malformed(name_, ".npy header " + what + " (at character " + std::to_string(pos_) + ")");
  }
  char Peek() const { return pos_ < t_.size() ? t_[pos_] : '\0'; }
  void Skip() {
    while (pos_ < t_.size() && (t_[pos_] == ' ' || t_[pos_] == '\n' || t_[pos_] == '\t')) ++pos_;
  }
  void Expect(char c) {
    Skip();
    if (Peek() != c) Fail(std::string("expected '") + c + "'");
    ++pos_;
  }
  std::string String() {
    Skip();
    const char quote = Peek();
    if (quote != '\'' && quote != '"') Fail("expected a string");
    const size_t end = t_.find(quote, pos_ + 1);
    if (end == std::string::npos) Fail("has an unterminated string");
    std::string s = t_.substr(pos_ + 1, end - pos_ - 1);
    pos_ = end + 1;
    return s;
  }
  bool Bool() {
    Skip();
    for (const char* word : {"True", "False"}) {
      if (t_.compare(pos_, std::strlen(word), word) == 0) {
        pos_ += std::strlen(word);
        return word[0] == 'T';
      }
    }
    Fail("expected True or False");
  }
  std::vector<uint64_t> Tuple() {
    Expect('(');
    std::vector<uint64_t> values;
    while (true) {
      Skip();
      if (Peek() == ')') break;
      if (Peek() < '0' || Peek() > '9') Fail("expected a non-negative integer in the shape");
      uint64_t v = 0;
      while (Peek() >= '0' && Peek() <= '9') {
        if (v > (std::numeric_limits<uint64_t>::max() - 9) / 10) Fail("has a shape too large");
        v = v * 10 + static_cast<uint64_t>(Peek() - '0');
        ++pos_;
      }
      if (Peek() == 'L') ++pos_;  // Python 2
      values.push_back(v);
      Skip();
      if (Peek() == ',') {
        ++pos_;
        continue;
      }
      if (Peek() != ')') Fail("expected ',' or ')' in the shape");
    }
    ++pos_;
    if (values.size() > 8) Fail("has more than 8 dimensions");
    return values;
  }

  const std::string& t_;
  std::string name_;
  size_t pos_ = 0;
};

}  // namespace

NpyArray ReadNpyHeader(ZipReader::Member* member, const std::string& name,
                       const std::string& descr) {
  unsigned char start[12];  // magic (6), version (2), header length (2 in 1.0, 4 in 2.0 and 3.0)
  member->Read(start, 8);
  if (std::memcmp(start, kNpyMagic, 6) != 0) Malformed(name, "is not an .npy array (bad magic)");
  const int major = start[6], minor = start[7];
  if (major < 1 || major > 3 || minor != 0) {
    Malformed(name, ".npy format version " + std::to_string(major) + "." + std::to_string(minor) +
                        " is not supported; expected 1.0, 2.0 or 3.0");
  }
  const int length_bytes = major == 1 ? 2 : 4;
  member->Read(start + 8, static_cast<size_t>(length_bytes));
  const uint64_t header_length = Get(start + 8, length_bytes);
  if (header_length > member->left() || header_length > (1u << 20)) {
    Malformed(name, ".npy header length " + std::to_string(header_length) + " exceeds the member");
  }
  std::string header(header_length, '\0');
  member->Read(header.data(), header.size());
  NpyArray a;
  bool fortran = false;
  NpyDictParser(header, name).Parse(&a, &fortran);
  if (a.descr != descr) {
    Malformed(name, ".npy descr '" + a.descr + "' is not supported; expected '" + descr + "'");
  }
  if (fortran) Malformed(name, ".npy fortran_order True is not supported; expected False");
  const uint64_t item = descr == "<f4" ? 4 : descr == "|b1" ? 1 : 8;
  a.count = 1;
  for (uint64_t d : a.shape) {
    if (d != 0 && a.count > std::numeric_limits<uint64_t>::max() / 8 / d) {
      Malformed(name, "shape is too large");
    }
    a.count *= d;
  }
  if (a.count * item != member->left()) {
    Malformed(name, "holds " + std::to_string(member->left()) + " data bytes; its shape needs " +
                        std::to_string(a.count * item));
  }
  return a;
}

void ExpectNpyShape(const NpyArray& a, const std::string& name, const std::vector<uint64_t>& shape,
                    const std::string& file_kind) {
  if (a.shape == shape) return;
  auto text = [](const std::vector<uint64_t>& s) {
    std::string t;
    for (uint64_t d : s) t += (t.empty() ? "" : ", ") + std::to_string(d);
    return "(" + t + (s.size() == 1 ? ",)" : ")");
  };
  throw InputError(
      name, "has shape " + text(a.shape) + "; expected " + text(shape) + "; not " + file_kind);
}

}  // namespace flexkin
