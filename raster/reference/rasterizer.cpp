// raster/reference/rasterizer.cpp — GL's triangle rasterization and per-fragment operations in
// double precision, written straight from the rules in docs/raster.md (no tiles, no floats).
#include "raster/reference/rasterizer.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace clvr::raster::reference {
namespace {

struct V {
    glm::dvec4 p;
    std::array<glm::dvec4, kMaxAttributes> a;
};

V mix(const V& in, const V& out, double t)
{
    V v;
    v.p = in.p + t * (out.p - in.p);
    for (int k = 0; k < kMaxAttributes; ++k)
        v.a[k] = in.a[k] + t * (out.a[k] - in.a[k]);
    return v;
}

// Sutherland–Hodgman, cutting each crossing edge from its inside end towards its outside end.
std::vector<V> clip(const std::vector<V>& poly, const glm::dvec4& plane)
{
    std::vector<V> out;
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const V& a = poly[i];
        const V& b = poly[(i + 1) % poly.size()];
        const double da = glm::dot(plane, a.p), db = glm::dot(plane, b.p);
        if (da >= 0.0)
            out.push_back(a);
        if (da >= 0.0 && db < 0.0)
            out.push_back(mix(a, b, da / (da - db)));
        else if (da < 0.0 && db >= 0.0)
            out.push_back(mix(b, a, db / (db - da)));
    }
    return out;
}

struct W {
    std::int64_t x, y;
    double z, invW;
    std::array<glm::dvec4, kMaxAttributes> aw;
};

std::int64_t edge(const W& a, const W& b, std::int64_t px, std::int64_t py)
{
    return (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x);
}

bool topLeft(const W& a, const W& b)
{
    return b.y < a.y || (b.y == a.y && b.x > a.x);
}

double blendFactor(BlendFactor f, const glm::dvec4& s, const glm::dvec4& d, const glm::dvec4& k, int c)
{
    switch (f) {
    case BlendFactor::Zero: return 0.0;
    case BlendFactor::One: return 1.0;
    case BlendFactor::SrcColor: return s[c];
    case BlendFactor::OneMinusSrcColor: return 1.0 - s[c];
    case BlendFactor::DstColor: return d[c];
    case BlendFactor::OneMinusDstColor: return 1.0 - d[c];
    case BlendFactor::SrcAlpha: return s.a;
    case BlendFactor::OneMinusSrcAlpha: return 1.0 - s.a;
    case BlendFactor::DstAlpha: return d.a;
    case BlendFactor::OneMinusDstAlpha: return 1.0 - d.a;
    case BlendFactor::ConstantColor: return k[c];
    case BlendFactor::OneMinusConstantColor: return 1.0 - k[c];
    case BlendFactor::ConstantAlpha: return k.a;
    case BlendFactor::OneMinusConstantAlpha: return 1.0 - k.a;
    case BlendFactor::SrcAlphaSaturate: return c == 3 ? 1.0 : std::min(s.a, 1.0 - d.a);
    }
    return 0.0;
}

double blendEquation(BlendEquation e, double s, double sf, double d, double df)
{
    switch (e) {
    case BlendEquation::Add: return s * sf + d * df;
    case BlendEquation::Subtract: return s * sf - d * df;
    case BlendEquation::ReverseSubtract: return d * df - s * sf;
    case BlendEquation::Min: return std::min(s, d);
    case BlendEquation::Max: return std::max(s, d);
    }
    return 0.0;
}

}  // namespace

Planes::Planes(int w, int h, glm::dvec4 c, double d, std::uint8_t s)
    : width(w), height(h), color(std::size_t(w) * h, c), depth(std::size_t(w) * h, d), stencil(std::size_t(w) * h, s)
{
}

Image4d Planes::colorImage() const
{
    Image4d image(width, height);
    image.pixels() = color;
    return image;
}

bool compare(CompareFunc func, double a, double b)
{
    switch (func) {
    case CompareFunc::Never: return false;
    case CompareFunc::Less: return a < b;
    case CompareFunc::Equal: return a == b;
    case CompareFunc::LEqual: return a <= b;
    case CompareFunc::Greater: return a > b;
    case CompareFunc::NotEqual: return a != b;
    case CompareFunc::GEqual: return a >= b;
    case CompareFunc::Always: return true;
    }
    return true;
}

std::uint8_t stencilOp(StencilOp op, std::uint8_t s, std::uint8_t ref, std::uint8_t writeMask)
{
    int v = s;
    switch (op) {
    case StencilOp::Keep: break;
    case StencilOp::Zero: v = 0; break;
    case StencilOp::Replace: v = ref; break;
    case StencilOp::Incr: v = std::min(s + 1, 255); break;
    case StencilOp::IncrWrap: v = (s + 1) % 256; break;
    case StencilOp::Decr: v = std::max(s - 1, 0); break;
    case StencilOp::DecrWrap: v = (s + 255) % 256; break;
    case StencilOp::Invert: v = 255 - s; break;
    }
    return static_cast<std::uint8_t>((s & ~writeMask) | (v & writeMask));
}

glm::dvec4 blend(const BlendState& b, const glm::dvec4& src, const glm::dvec4& dst)
{
    const glm::dvec4 k(b.constant);
    glm::dvec4 out;
    for (int c = 0; c < 4; ++c) {
        const BlendEquation e = c == 3 ? b.alphaEquation : b.rgbEquation;
        const BlendFactor sf = c == 3 ? b.srcAlpha : b.srcRgb;
        const BlendFactor df = c == 3 ? b.dstAlpha : b.dstRgb;
        out[c] = blendEquation(e, src[c], blendFactor(sf, src, dst, k, c), dst[c], blendFactor(df, src, dst, k, c));
    }
    return out;
}

DrawStats draw(Planes& fb, const DrawState& state, Topology topology, const std::vector<Vertex>& vertices,
               const FragmentFunction& program)
{
    const FragmentState& fs = state.fragment;
    const Viewport& v = state.viewport;
    const double vw = v.width < 0 ? fb.width : v.width, vh = v.height < 0 ? fb.height : v.height;
    const double n = std::clamp(double(v.nearZ), 0.0, 1.0), f = std::clamp(double(v.farZ), 0.0, 1.0);
    const int sx0 = std::max(v.x, 0), sy0 = std::max(v.y, 0);
    const int sx1 = std::min(v.x + int(vw), fb.width), sy1 = std::min(v.y + int(vh), fb.height);  // exclusive

    std::vector<glm::dvec4> planes{{0, 0, 1, 1}, {0, 0, -1, 1}};
    for (const glm::vec4& p : state.clipPlanes)
        planes.emplace_back(p);
    const double gx = 1.0 + 2.0 * kGuardBandPixels / vw, gy = 1.0 + 2.0 * kGuardBandPixels / vh;
    planes.insert(planes.end(), {{-1, 0, 0, gx}, {1, 0, 0, gx}, {0, -1, 0, gy}, {0, 1, 0, gy}});

    std::vector<std::array<std::size_t, 3>> tris;
    const std::size_t count = vertices.size();
    for (std::size_t i = 0; i + 2 < count; ++i) {
        if (topology == Topology::Triangles) {
            if (i % 3 == 0)
                tris.push_back({i, i + 1, i + 2});
        } else if (topology == Topology::TriangleStrip) {
            tris.push_back(i % 2 ? std::array<std::size_t, 3>{i + 1, i, i + 2} : std::array<std::size_t, 3>{i, i + 1, i + 2});
        } else {
            tris.push_back({0, i + 1, i + 2});
        }
    }

    DrawStats stats;
    for (const auto& t : tris) {
        std::vector<V> poly;
        for (std::size_t i : t) {
            V vv{glm::dvec4(vertices[i].position), {}};
            for (int k = 0; k < kMaxAttributes; ++k)
                vv.a[k] = glm::dvec4(vertices[i].attributes[k]);
            poly.push_back(vv);
        }
        for (const glm::dvec4& p : planes)
            if (poly.size() >= 3)
                poly = clip(poly, p);
        if (poly.size() < 3)
            continue;
        std::vector<W> win;
        bool ok = true;
        for (const V& c : poly) {
            if (!(c.p.w > 0.0)) {
                ok = false;
                break;
            }
            const double ndcX = c.p.x / c.p.w, ndcY = c.p.y / c.p.w, ndcZ = c.p.z / c.p.w;
            W w;
            w.x = std::int64_t(std::floor((v.x + (ndcX + 1.0) * 0.5 * vw) * CLVR_SUBPIXEL_SCALE + 0.5));
            w.y = std::int64_t(std::floor((v.y + (1.0 - ndcY) * 0.5 * vh) * CLVR_SUBPIXEL_SCALE + 0.5));
            w.z = n + (ndcZ + 1.0) * 0.5 * (f - n);
            w.invW = 1.0 / c.p.w;
            for (int k = 0; k < kMaxAttributes; ++k)
                w.aw[k] = c.a[k] * w.invW;
            win.push_back(w);
        }
        if (!ok)
            continue;
        std::int64_t area = 0;
        for (std::size_t i = 1; i + 1 < win.size(); ++i)
            area += edge(win[0], win[i], win[i + 1].x, win[i + 1].y);
        if (area == 0)
            continue;
        const bool front = fs.frontFaceCCW ? area < 0 : area > 0;  // y flip: CCW with y up is area < 0 here
        if (fs.cull == CullFace::FrontAndBack || (fs.cull == CullFace::Front && front) ||
            (fs.cull == CullFace::Back && !front))
            continue;

        for (std::size_t i = 1; i + 1 < win.size(); ++i) {
            W a = win[0], b = win[i], c = win[i + 1];
            const std::int64_t a2 = edge(a, b, c.x, c.y);
            if (a2 == 0 || (a2 > 0) != (area > 0))
                continue;
            if (a2 < 0)
                std::swap(b, c);
            ++stats.triangles;
            const double inv = 1.0 / double(std::llabs(a2));
            for (int py = sy0; py < sy1; ++py)
                for (int px = sx0; px < sx1; ++px) {
                    const std::int64_t cx = std::int64_t(px) * CLVR_SUBPIXEL_SCALE + CLVR_SUBPIXEL_SCALE / 2;
                    const std::int64_t cy = std::int64_t(py) * CLVR_SUBPIXEL_SCALE + CLVR_SUBPIXEL_SCALE / 2;
                    const std::int64_t eab = edge(a, b, cx, cy), ebc = edge(b, c, cx, cy), eca = edge(c, a, cx, cy);
                    const auto in = [](std::int64_t e, bool tl) { return e > 0 || (e == 0 && tl); };
                    if (!in(eab, topLeft(a, b)) || !in(ebc, topLeft(b, c)) || !in(eca, topLeft(c, a)))
                        continue;
                    ++stats.fragments;
                    const double la = ebc * inv, lb = eca * inv, lc = eab * inv;
                    Fragment frag;
                    frag.window = {px + 0.5, py + 0.5};
                    frag.depth = la * a.z + lb * b.z + lc * c.z;
                    frag.frontFacing = front;
                    const double oneOverW = la * a.invW + lb * b.invW + lc * c.invW;
                    for (int k = 0; k < kMaxAttributes; ++k)
                        frag.attributes[k] = (la * a.aw[k] + lb * b.aw[k] + lc * c.aw[k]) / oneOverW;

                    glm::dvec4 src = frag.attributes[0];
                    if (program && !program(frag, src))
                        continue;
                    const std::size_t p = std::size_t(py) * fb.width + px;
                    if (fs.alpha.test && !compare(fs.alpha.func, src.a, std::clamp(double(fs.alpha.ref), 0.0, 1.0)))
                        continue;
                    std::uint8_t& s = fb.stencil[p];
                    const StencilState& st = fs.stencil;
                    if (st.test && !compare(st.func, st.ref & st.readMask, s & st.readMask)) {
                        s = stencilOp(st.sfail, s, st.ref, st.writeMask);
                        continue;
                    }
                    if (fs.depth.test) {
                        if (!compare(fs.depth.func, frag.depth, fb.depth[p])) {
                            if (st.test)
                                s = stencilOp(st.dpfail, s, st.ref, st.writeMask);
                            continue;
                        }
                        if (fs.depth.write)
                            fb.depth[p] = frag.depth;
                    }
                    if (st.test)
                        s = stencilOp(st.dppass, s, st.ref, st.writeMask);
                    const glm::dvec4 out = fs.blend.enabled ? blend(fs.blend, src, fb.color[p]) : src;
                    const bool mask[4] = {fs.colorMask.r, fs.colorMask.g, fs.colorMask.b, fs.colorMask.a};
                    for (int ch = 0; ch < 4; ++ch)
                        if (mask[ch])
                            fb.color[p][ch] = out[ch];
                }
        }
    }
    return stats;
}

}  // namespace clvr::raster::reference
