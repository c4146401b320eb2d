#pragma once

#include <regex.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace drt::test {

// POSIX extended regular expressions for checking drt's printed lines. libc's regex rather than
// std::regex, whose GCC 12 templates print -Wmaybe-uninitialized warnings under the sanitizers.

// The leftmost match of `pattern` in `text` and its parenthesised groups (empty strings for
// groups that took no part), or an empty vector when nothing matches.
inline std::vector<std::string> regex_groups(const std::string& text, const char* pattern) {
    regex_t compiled;
    if (regcomp(&compiled, pattern, REG_EXTENDED) != 0) throw std::invalid_argument(pattern);
    std::vector<regmatch_t> match(compiled.re_nsub + 1);
    const bool found = regexec(&compiled, text.c_str(), match.size(), match.data(), 0) == 0;
    regfree(&compiled);
    std::vector<std::string> groups;
    if (!found) return groups;
    for (const regmatch_t& m : match)
        groups.push_back(m.rm_so < 0 ? std::string() : text.substr(m.rm_so, m.rm_eo - m.rm_so));
    return groups;
}

// Group 1 of every match of `pattern` (which must have a group) in `text`, left to right.
inline std::vector<std::string> regex_all_groups(const std::string& text, const char* pattern) {
    regex_t compiled;
    if (regcomp(&compiled, pattern, REG_EXTENDED) != 0) throw std::invalid_argument(pattern);
    if (compiled.re_nsub < 1) {
        regfree(&compiled);
        throw std::invalid_argument(pattern);
    }
    std::vector<std::string> out;
    regmatch_t match[2];
    for (const char* at = text.c_str(); *at != '\0';) {
        if (regexec(&compiled, at, 2, match, at == text.c_str() ? 0 : REG_NOTBOL) != 0) break;
        if (match[1].rm_so >= 0) out.emplace_back(at + match[1].rm_so, at + match[1].rm_eo);
        at += match[0].rm_eo > 0 ? match[0].rm_eo : 1;  // an empty match moves on by one
    }
    regfree(&compiled);
    return out;
}

// The length of the leftmost match of `pattern` in `text`, or -1.
inline long regex_match_length(const std::string& text, const char* pattern) {
    const std::vector<std::string> groups = regex_groups(text, pattern);
    return groups.empty() ? -1 : static_cast<long>(groups[0].size());
}

inline bool regex_search(const std::string& text, const char* pattern) {
    return !regex_groups(text, pattern).empty();
}

}  // namespace drt::test
