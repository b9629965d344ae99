#pragma once

#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <fast_float/fast_float.h>

namespace subscan {

/// `text` with its ASCII letters in lower case (file extensions, format names).
inline std::string asciiLowercase(std::string_view text) {
    std::string lower(text);
    for (char& c : lower) {
        c = c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
    }
    return lower;
}

inline bool isBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r';
}
inline bool isWhitespace(char c) {
    return isBlank(c) || c == '\n' || c == '\v' || c == '\f';
}

/// Parses one decimal number (optionally signed; "nan"/"inf" allowed so callers can drop such
/// points) starting exactly at `first`. Returns the end of the number, or nullptr if there is
/// none or it runs straight into a character that cannot end a number.
inline const char* parseNumber(const char* first, const char* last, double& value) {
    const char* start = first;
    if (start != last && *start == '+') {
        ++start;  // fast_float rejects a leading '+', which some exporters write.
    }
    const fast_float::from_chars_result result = fast_float::from_chars(start, last, value);
    if (result.ec != std::errc() || result.ptr == start) {
        return nullptr;
    }
    return result.ptr;
}

/// Splits on runs of whitespace into `words`, which keeps its capacity for the next line.
inline void splitWords(std::string_view line, std::vector<std::string_view>& words) {
    words.clear();
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && isWhitespace(line[i])) {
            ++i;
        }
        std::size_t j = i;
        while (j < line.size() && !isWhitespace(line[j])) {
            ++j;
        }
        if (j > i) {
            words.push_back(line.substr(i, j - i));
        }
        i = j;
    }
}

/// Splits on runs of whitespace.
inline std::vector<std::string_view> splitWords(std::string_view line) {
    std::vector<std::string_view> words;
    splitWords(line, words);
    return words;
}

/// A printable, bounded excerpt of untrusted text for error messages.
inline std::string quoteForMessage(std::string_view text, std::size_t maxLength = 40) {
    std::string out = "'";
    for (std::size_t i = 0; i < text.size() && i < maxLength; ++i) {
        const unsigned char c = static_cast<unsigned char>(text[i]);
        out += (c >= 32 && c < 127) ? static_cast<char>(c) : '?';
    }
    if (text.size() > maxLength) {
        out += "...";
    }
    return out + "'";
}

}  // namespace subscan
