// Stored answers of test_stored_answers.cpp: plain-text files (one per URDF,
// holding one or more scenes), one line per answer array,
//   <key> <count> <value> ... <value>
// with numbers as C99 hex floats (printf "%a", read back by strtod: every bit
// kept; float32 answers are stored as the doubles they convert to) and names
// as whitespace-free tokens. An array identical to one written before it is
// written as "<key> = <earlier key>" (fewer bytes; it is compared with
// those values all the same). Lines starting with '#' are comments. Keys
// are "<scene>/<array>" or "<scene>/<body>/<array>".
//
// AnswerBook either records the arrays of one scene and writes its file
// (generation), or compares each array with the stored one as it is
// produced, by the rule of its Match:
//   Exact      every bit (memcmp; names: equal strings);
//   Tolerance  doubles: |now - stored| <= 8 eps max(1, max_j |stored_j|) per
//              entry (eps = DBL_EPSILON, max over that array);
//              float32: now == stored or one float ulp from it.
// Failure messages name the scene, body, array and index, and print both
// values as hex floats and in decimal.
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace drb_test
{
namespace stored_answers
{
enum class Match
{
  Exact,
  Tolerance
};

inline std::string hexFloat(double value)
{
  char text[64];
  std::snprintf(text, sizeof text, "%a", value);
  return text;
}

/// "0x1.8p+1 (3)": a value as stored and in decimal, for messages.
inline std::string describe(double value)
{
  char text[96];
  std::snprintf(text, sizeof text, "%a (%.17g)", value, value);
  return text;
}

/// FNV-1a, 64 bits: seeds and the fingerprint of a scene's URDF text.
inline std::uint64_t fnv1a64(const std::string& text)
{
  std::uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : text)
    hash = (hash ^ c) * 1099511628211ull;
  return hash;
}

/// fnv1a64 as 16 hex digits.
inline std::string fingerprint(const std::string& text)
{
  char digits[17];
  std::snprintf(digits, sizeof digits, "%016llx", static_cast<unsigned long long>(fnv1a64(text)));
  return digits;
}

/// Why `now` does not match `stored` under `match` (both values); "" when it does.
template <typename T>
std::string entryMismatch(T stored, T now, Match match, double tolerance)
{
  if (std::memcmp(&stored, &now, sizeof(T)) == 0)
    return "";
  if (match == Match::Tolerance)
  {
    if (sizeof(T) == sizeof(double) && std::fabs(double(now) - double(stored)) <= tolerance)
      return "";
    if (sizeof(T) == sizeof(float) && (now == std::nextafter(stored, T(INFINITY)) ||
                                       now == std::nextafter(stored, T(-INFINITY))))
      return "";
  }
  return "stored " + describe(double(stored)) + ", now " + describe(double(now));
}

class AnswerBook
{
public:
  /// The answers of file `<name>.txt`: written to `write_dir` when it is not
  /// empty, else compared with the file in `stored_dir`.
  AnswerBook(std::string name, const std::string& stored_dir, std::string write_dir)
    : name_(std::move(name)), write_dir_(std::move(write_dir))
  {
    if (!writing())
      read(stored_dir + "/" + name_ + ".txt");
  }

  bool writing() const { return !write_dir_.empty(); }

  /// The scene whose arrays follow (the first part of their keys); one file
  /// may hold several, e.g. one URDF loaded with different options.
  void beginScene(const std::string& scene) { scene_ = scene; }

  void names(const std::string& body, const std::string& array, const std::vector<std::string>& values)
  {
    const std::string key = keyOf(body, array);
    if (writing())
      return record(key, values);
    const std::vector<std::string>* stored = lookUp(key, values.size(), body, array);
    for (std::size_t i = 0; stored && i < values.size(); ++i)
      EXPECT_EQ((*stored)[i], values[i]) << where(body, array, static_cast<long>(i));
  }

  /// Doubles or floats (as the doubles they convert to).
  template <typename T>
  void numbers(const std::string& body, const std::string& array, const std::vector<T>& values, Match match)
  {
    const std::string key = keyOf(body, array);
    if (writing())
    {
      std::vector<std::string> tokens;
      for (T value : values)
        tokens.push_back(hexFloat(double(value)));
      return record(key, tokens);
    }
    const std::vector<std::string>* stored = lookUp(key, values.size(), body, array);
    if (stored)
      compare(body, array, *stored, values, match);
  }

  /// Writes the file, or fails for every stored array that was not produced.
  void finish()
  {
    if (writing())
      return write();
    for (const auto& entry : stored_)
      if (!seen_.count(entry.first))
        ADD_FAILURE() << name_ << ".txt: stored array '" << entry.first << "' was not produced";
  }

private:
  std::string keyOf(const std::string& body, const std::string& array) const
  {
    return scene_ + "/" + (body.empty() ? "" : body + "/") + array;
  }

  /// "scene s, body 'b', array 'a'", then " [index]" when one is given.
  std::string where(const std::string& body, const std::string& array, long index = -1) const
  {
    return "scene " + scene_ + ", " + (body.empty() ? "" : "body '" + body + "', ") + "array '" + array + "'" +
           (index < 0 ? "" : " [" + std::to_string(index) + "]");
  }

  void record(const std::string& key, const std::vector<std::string>& tokens)
  {
    for (const std::string& token : tokens)
      if (token.empty() || token.find_first_of(" \t\r\n") != std::string::npos)
        ADD_FAILURE() << key << ": cannot store the token '" << token << "' (empty or with whitespace)";
    if (!stored_.emplace(key, tokens).second)
      ADD_FAILURE() << key << ": produced twice";
    for (const std::string& earlier : order_)
      if (tokens.size() >= 4 && stored_.at(earlier) == tokens && !aliases_.count(key))
        aliases_[key] = earlier;
    order_.push_back(key);
  }

  const std::vector<std::string>* lookUp(const std::string& key, std::size_t count, const std::string& body,
                                         const std::string& array)
  {
    if (!seen_.insert(key).second)
      ADD_FAILURE() << key << ": produced twice";
    const auto found = stored_.find(key);
    if (found == stored_.end())
    {
      ADD_FAILURE() << where(body, array) << ": no stored answer (key " << key << ")";
      return nullptr;
    }
    if (found->second.size() != count)
    {
      ADD_FAILURE() << where(body, array) << ": " << count << " values now, " << found->second.size() << " stored";
      return nullptr;
    }
    return &found->second;
  }

  template <typename T>
  void compare(const std::string& body, const std::string& array, const std::vector<std::string>& stored,
               const std::vector<T>& values, Match match)
  {
    std::vector<T> expected(stored.size());
    double largest = 1.0;
    for (std::size_t i = 0; i < stored.size(); ++i)
    {
      expected[i] = static_cast<T>(std::strtod(stored[i].c_str(), nullptr));
      largest = std::max(largest, std::fabs(double(expected[i])));
    }
    const double tolerance = 8 * DBL_EPSILON * largest;
    std::size_t failures = 0;
    for (std::size_t i = 0; i < values.size(); ++i)
    {
      const std::string mismatch = entryMismatch(expected[i], values[i], match, tolerance);
      if (!mismatch.empty() && ++failures <= 5)
        ADD_FAILURE() << where(body, array, static_cast<long>(i)) << ": " << mismatch
                      << (match == Match::Exact  ? " (must match bit for bit)" :
                          sizeof(T) == sizeof(float) ? " (one float ulp allowed)" :
                                                       " (tolerance " + describe(tolerance) + ")");
    }
    if (failures > 5)
      ADD_FAILURE() << where(body, array) << ": " << failures << " of " << values.size()
                    << " entries differ (first 5 shown)";
  }

  void read(const std::string& path)
  {
    std::ifstream file(path);
    if (!file)
    {
      ADD_FAILURE() << "cannot read the stored answers " << path;
      return;
    }
    std::string line;
    while (std::getline(file, line))
    {
      if (line.empty() || line[0] == '#')
        continue;
      std::istringstream fields(line);
      std::string key, count_or_alias;
      fields >> key >> count_or_alias;
      if (count_or_alias == "=")
      {
        std::string earlier;
        fields >> earlier;
        if (!stored_.count(earlier))
          ADD_FAILURE() << path << ": line '" << key << "' repeats '" << earlier << "', which no earlier line stores";
        stored_[key] = stored_[earlier];
        continue;
      }
      const std::size_t count = std::strtoull(count_or_alias.c_str(), nullptr, 10);
      std::vector<std::string>& tokens = stored_[key];
      for (std::string token; tokens.size() < count && fields >> token;)
        tokens.push_back(token);
      if (tokens.size() != count)
        ADD_FAILURE() << path << ": line '" << key << "' announces " << count << " values, holds " << tokens.size();
    }
  }

  void write() const
  {
    const std::string path = write_dir_ + "/" + name_ + ".txt";
    std::ofstream file(path);
    file << "# Stored answers (" << name_ << "): see test/unit/test_stored_answers.cpp.\n"
         << "# <key> <count> <values>; numbers are C99 hex floats (%a).\n";
    for (const std::string& key : order_)
    {
      if (aliases_.count(key))
      {
        file << key << " = " << aliases_.at(key) << '\n';
        continue;
      }
      file << key << ' ' << stored_.at(key).size();
      for (const std::string& token : stored_.at(key))
        file << ' ' << token;
      file << '\n';
    }
    if (!file.flush())
      ADD_FAILURE() << "cannot write " << path;
    else
      std::cout << "[ NOTE     ] wrote " << order_.size() << " answer arrays to " << path
                << " (not compared)\n";
  }

  std::string name_;
  std::string scene_;
  std::string write_dir_;
  std::map<std::string, std::vector<std::string>> stored_;
  std::vector<std::string> order_;  ///< keys in the order produced (writing)
  std::map<std::string, std::string> aliases_;  ///< key -> earlier key of the same values (writing)
  std::set<std::string> seen_;      ///< keys produced (comparing)
};

}  // namespace stored_answers
}  // namespace drb_test
