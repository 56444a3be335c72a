// The world reader's tokenizer (src/world/world_reader.cpp only): whitespace-separated tokens with
// their line numbers, pulled in 64 KiB chunks from a text or a stream so that a file is never
// held whole, and the log of the positions' and velocities' tokens kept for error messages.
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <istream>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "src/world/world_reader.h"

namespace jello::reader {

// A file past the reader's size limit, found before reading (its size) or while reading (a pipe).
inline WorldFileError fileTooLarge(const std::string& name, std::uintmax_t maxBytes) {
  return WorldFileError(
      name, 0, name,
      "file is larger than the reader allows (" + std::to_string(maxBytes) + " bytes)");
}

constexpr std::string_view kEndOfFile = "<end of file>";

// A token as the reader keeps it: its first kMaxTokenBytes bytes (a longer one cannot be a
// number or a keyword, and a 50 MB "number" is never held whole) and its full length.
constexpr std::size_t kMaxTokenBytes = 4096;
struct Token {
  std::string text;  // empty at end of file
  std::size_t bytes = 0;
  int line = 0;
};

// Where the tokenizer's bytes come from: a text already in memory, or a stream read in chunks so
// that a file is never held whole (refused early, in bounded memory).
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Up to `n` bytes into `buf`; 0 at the end.
  virtual std::size_t read(char* buf, std::size_t n) = 0;
};

class TextSource final : public ByteSource {
 public:
  explicit TextSource(std::string_view text) : text_(text) {}
  std::size_t read(char* buf, std::size_t n) override {
    const std::size_t got = std::min(n, text_.size());
    std::copy_n(text_.data(), got, buf);
    text_.remove_prefix(got);
    return got;
  }

 private:
  std::string_view text_;
};

class StreamSource final : public ByteSource {
 public:
  StreamSource(std::istream& in, std::string name) : in_(in), name_(std::move(name)) {}
  std::size_t read(char* buf, std::size_t n) override {
    in_.read(buf, static_cast<std::streamsize>(n));
    if (in_.bad()) throw WorldFileError(name_, 0, name_, "read failed");
    return static_cast<std::size_t>(in_.gcount());
  }

 private:
  std::istream& in_;
  std::string name_;
};

// Whitespace-separated tokens with their line numbers, read in 64 KiB chunks. '\r' is white
// space, so CRLF files read like LF files, as with the original fscanf loader. `totalBytes` is
// the input's size when known (0: unknown); `maxBytes` refuses a larger input once it is passed.
class Tokenizer {
 public:
  Tokenizer(ByteSource& source, std::string name, std::uintmax_t totalBytes,
            std::uintmax_t maxBytes)
      : source_(source), name_(std::move(name)), total_(totalBytes), max_(maxBytes) {
    // A UTF-8 byte-order mark (some editors write one) is not part of the first token.
    while (end_ < 3 && fill()) {
    }
    if (std::string_view(buffer_.data(), std::min<std::size_t>(end_, 3)) == "\xEF\xBB\xBF") {
      pos_ = 3;
    }
  }

  Token next() {
    skipSpace();
    lastToken_.text.clear();
    lastToken_.bytes = 0;
    lastToken_.line = line_;
    while (pos_ < end_ || fill()) {
      std::size_t stop = pos_;
      while (stop < end_ && !isSpace(buffer_[stop])) ++stop;
      const std::size_t n = stop - pos_;
      const std::size_t keep = std::min(n, kMaxTokenBytes - lastToken_.text.size());
      lastToken_.text.append(buffer_.data() + pos_, keep);
      lastToken_.bytes += n;
      pos_ = stop;
      if (stop < end_) break;
    }
    return lastToken_;
  }

  // Bytes not yet read, when the input's size is known; otherwise the largest possible count.
  std::uintmax_t remainingBytes() const {
    if (total_ == 0) return std::numeric_limits<std::uintmax_t>::max();
    const std::uintmax_t used = consumed_ - (end_ - pos_);
    return used < total_ ? total_ - used : 0;
  }

  [[noreturn]] void fail(const Token& t, const std::string& message) const {
    if (t.text.empty()) throw WorldFileError(name_, t.line, std::string(kEndOfFile), message);
    throw WorldFileError(name_, t.line, t.text, message, t.bytes);
  }

  double number(const char* what) {
    const Token t = next();
    return toNumber(t, what);
  }

  double toNumber(const Token& t, const char* what) const {
    if (t.text.empty()) fail(t, std::string("file ends where ") + what + " was expected");
    if (t.bytes > t.text.size()) fail(t, std::string("expected a number for ") + what);
    std::string_view s = t.text;
    if (s.size() > 1 && s[0] == '+' && s[1] != '-') s.remove_prefix(1);  // fscanf accepts "+1"
    double value = 0.0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec == std::errc::result_out_of_range) fail(t, std::string(what) + " is out of range");
    if (ec != std::errc() || end != s.data() + s.size()) {
      fail(t, std::string("expected a number for ") + what);
    }
    if (!std::isfinite(value)) fail(t, std::string(what) + " must be finite");
    return value;
  }

  // `hint` is added to the message when the token is not an integer.
  int integer(const char* what, const std::string& hint = {}) {
    const Token t = next();
    if (t.text.empty()) fail(t, std::string("file ends where ") + what + " was expected");
    int value = 0;
    std::string_view s = t.text;
    if (s.size() > 1 && s[0] == '+' && s[1] != '-') s.remove_prefix(1);
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec == std::errc::result_out_of_range) fail(t, std::string(what) + " is out of range");
    if (ec != std::errc() || end != s.data() + s.size() || t.bytes > t.text.size()) {
      fail(t, std::string("expected an integer for ") + what + hint);
    }
    return value;
  }

  double positive(const char* what) {
    const Token t = next();
    const double v = toNumber(t, what);
    if (!(v > 0.0)) fail(t, std::string(what) + " must be positive");
    return v;
  }

  double nonNegative(const char* what) {
    const Token t = next();
    const double v = toNumber(t, what);
    if (v < 0.0) fail(t, std::string(what) + " must not be negative");
    return v;
  }

  const Token& lastToken() const { return lastToken_; }

 private:
  static bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
  }
  // Refills the buffer (keeping nothing: tokens are copied out as they are read); false at the end.
  bool fill() {
    if (eof_) return false;
    if (pos_ == end_) pos_ = end_ = 0;
    const std::size_t got = source_.read(buffer_.data() + end_, buffer_.size() - end_);
    if (got == 0) {
      eof_ = true;
      return false;
    }
    end_ += got;
    consumed_ += got;
    if (consumed_ > max_) {
      throw fileTooLarge(name_, max_);
    }
    return true;
  }
  void skipSpace() {
    while (pos_ < end_ || fill()) {
      while (pos_ < end_ && isSpace(buffer_[pos_])) {
        if (buffer_[pos_] == '\n') ++line_;
        ++pos_;
      }
      if (pos_ < end_) return;
    }
  }

  ByteSource& source_;
  std::string name_;
  std::uintmax_t total_;
  std::uintmax_t max_;
  std::vector<char> buffer_ = std::vector<char>(1 << 16);
  std::size_t pos_ = 0, end_ = 0;
  std::uintmax_t consumed_ = 0;
  bool eof_ = false;
  int line_ = 1;
  Token lastToken_;
};

// The tokens of the positions and velocities, kept for error messages only: their line, length
// and the bytes a message shows, packed in one string (1.5 million of them for a 64^3 cube).
class TokenLog {
 public:
  void reserve(std::size_t n) { entries_.reserve(n); }
  void add(const Token& t) {
    const std::size_t keep = std::min(t.text.size(), kShownBytes);
    entries_.push_back({static_cast<std::uint32_t>(shown_.size()),
                        static_cast<std::uint32_t>(std::min<std::size_t>(t.bytes, UINT32_MAX)),
                        static_cast<std::uint8_t>(keep), t.line});
    shown_.append(t.text, 0, keep);
  }
  bool empty() const { return entries_.empty(); }
  Token operator[](std::size_t i) const {
    const Entry& e = entries_[i];
    return {shown_.substr(e.offset, e.kept), e.bytes, e.line};
  }
  Token back() const { return (*this)[entries_.size() - 1]; }

 private:
  static constexpr std::size_t kShownBytes = 41;  // one more than a message shows
  struct Entry {                                  // 16 bytes
    std::uint32_t offset;
    std::uint32_t bytes;
    std::uint8_t kept;
    int line;
  };
  std::vector<Entry> entries_;
  std::string shown_;
};

}  // namespace jello::reader
