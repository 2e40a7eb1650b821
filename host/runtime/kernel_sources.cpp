// host/runtime/kernel_sources.cpp — one embedded kernel's source by file name.
#include "host/runtime/embedded_kernels.h"

#include "host/runtime/errors.h"

#include <regex>
#include <string>

namespace clvr {

std::string_view embeddedKernelSource(std::string_view name)
{
    for (const EmbeddedKernel& k : embeddedKernels())
        if (k.name == name)
            return k.source;
    throw InternalError("kernels/" + std::string(name) + " is not embedded in this build");
}

std::string mapSourcePositions(std::string_view source, std::string_view log)
{
    static const std::regex position(R"re(<[A-Za-z ]{1,32}>:([0-9]{1,9}))re");
    const std::string text(log);
    if (!std::regex_search(text, position))
        return text;  // nothing to map (PoCL and Mesa name files themselves): the source is not read

    // Where each line of the submitted source comes from: a "#line N \"file\"" marker says the next
    // line is line N of file (the file unchanged when the marker names none).
    struct Origin {
        std::string file;
        long line = 0;
    };
    std::vector<Origin> origins;  // origins[r - 1]: line r of `source`
    static const std::regex marker(R"re(^[ \t]*#[ \t]*line[ \t]+([0-9]+)(?:[ \t]+"([^"]*)")?)re");
    Origin next{"", 1};
    std::string line;
    std::size_t begin = 0;
    while (begin <= source.size()) {
        std::size_t end = source.find('\n', begin);
        if (end == std::string_view::npos)
            end = source.size();
        const std::string_view view = source.substr(begin, end - begin);
        origins.push_back(next);
        std::smatch m;
        bool isMarker = false;
        if (const std::size_t first = view.find_first_not_of(" \t"); first != std::string_view::npos && view[first] == '#') {
            line.assign(view);  // only directives go through the regex
            isMarker = std::regex_search(line, m, marker);
        }
        if (isMarker) {
            next.line = std::stol(m[1].str());
            if (m[2].matched)
                next.file = m[2].str();
        } else {
            ++next.line;
        }
        begin = end + 1;
    }

    std::string mapped;
    auto last = text.cbegin();
    for (std::sregex_iterator it(text.begin(), text.end(), position), done; it != done; ++it) {
        const std::smatch& m = *it;
        const long raw = std::stol(m[1].str());
        mapped.append(last, m[0].first);
        if (raw >= 1 && raw <= static_cast<long>(origins.size()) && !origins[raw - 1].file.empty())
            mapped += origins[raw - 1].file + ":" + std::to_string(origins[raw - 1].line);
        else
            mapped.append(m[0].first, m[0].second);
        last = m[0].second;
    }
    mapped.append(last, text.cend());
    return mapped;
}

}  // namespace clvr
