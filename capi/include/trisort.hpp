/**
 * @file trisort.hpp
 * @brief A header-only C++17 wrapper over the trisort C API (trisort.h).
 *
 * What it adds to trisort.h, and nothing else:
 *
 * - **Owning handles.** trisort::Baked (a baked file) and trisort::Order (an ORDER file) own
 *   their C handle and close it in their destructor. They are move-only; a moved-from object
 *   holds no handle, and its functions fail with TRISORT_STATUS_NULL_ARGUMENT.
 * - **Copies into std::vector.** Every array is copied out with the C API's two-call copy
 *   convention (once with `out = NULL` for the length, then into a vector of that length), so
 *   the host owns what it gets. Strings come back as std::string, 4×4 matrices as
 *   trisort::Matrix (16 floats, column major, as trisort.h says).
 * - **Errors as exceptions or as `expected`.** By default a failed call throws
 *   trisort::Error (a std::runtime_error) holding the TrisortStatus and the message of
 *   trisort_last_error(). Define `TRISORT_HPP_NO_EXCEPTIONS` before including this header
 *   (the same way in every translation unit of a program) and every function that can fail
 *   returns trisort::expected<T> instead, which holds either the value or the trisort::Error,
 *   and the header itself never throws (it builds with `-fno-exceptions`).
 *   trisort::result<T> names what a function returns in the chosen mode (`T` or
 *   `trisort::expected<T>`).
 *
 * trisort::expected<T> is `std::expected<T, trisort::Error>` where the standard library has
 * it (`__cpp_lib_expected`, C++23) and `TRISORT_HPP_NO_STD_EXPECTED` is not defined; otherwise
 * a small class of this header with the same names for the same things: has_value(),
 * `explicit operator bool`, value(), error(), `operator*`, `operator->`, value_or().
 *
 * Conventions, thread safety and lifetimes are the C API's (the top of trisort.h): a handle
 * may be read from several threads at once; an Error reads the calling thread's last error
 * right after the call that failed. Wrapped: the functions of ABI 4; format_version(),
 * version_string() and the `trisort_gpu_*` functions (Baked::gpu_frame_uniform() and the
 * rest, with the enums Shading, ToneMap and TextureArray) when the included trisort.h is of
 * ABI 5 or later; Baked::clips() and Baked::find_clip() when it is of ABI 6 or later. Not
 * wrapped: writing ORDER files (trisort_export_order(), libtrisort_export).
 *
 * @code
 * #include <trisort.hpp>
 *
 * trisort::Baked baked = trisort::Baked::open("car.baked");        // throws trisort::Error
 * TrisortInfo info = baked.info();
 * std::vector<std::uint32_t> indices = baked.indices_u32(true);     // back to front
 * for (std::uint32_t f = 0; f < info.frame_count; ++f) {
 *     std::vector<TrisortDrawIndexedIndirectArgs> draws = baked.frame_draws(f, true);
 *     trisort::Matrix view = baked.frame_view(f);
 *     trisort::Matrix projection =
 *         baked.frame_projection(f, 16.0 / 9.0, trisort::DepthRange::MinusOneToOne);
 *     // ... upload and draw
 * }
 * @endcode
 */
#ifndef TRISORT_HPP
#define TRISORT_HPP

#include "trisort.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#if defined(__has_include)
#if __has_include(<version>)
#include <version>
#endif
#endif

#if defined(__cpp_lib_span) && __cpp_lib_span >= 202002L
#include <span>
#endif

#if defined(__cpp_lib_expected) && __cpp_lib_expected >= 202202L && \
    !defined(TRISORT_HPP_NO_STD_EXPECTED)
#include <expected>
/** Defined to 1 when trisort::expected is std::expected (else not defined). */
#define TRISORT_HPP_STD_EXPECTED 1
#endif

/** The trisort C API's C++ wrapper. */
namespace trisort {

/** A 4×4 matrix: 16 floats, column major (element (r, c) at index 4 * c + r). */
using Matrix = std::array<float, 16>;

/**
 * A clip-space depth convention, for Baked::frame_projection(). Its values are trisort.h's
 * `TRISORT_DEPTH_RANGE_*`.
 */
enum class DepthRange : std::uint32_t {
    /** Depth in [0, 1] (Vulkan, Direct3D, Metal, WebGPU: what trisort records with). */
    ZeroToOne = 0,
    /** Depth in [-1, 1] (OpenGL and OpenGL ES defaults). */
    MinusOneToOne = 1,
};
static_assert(static_cast<std::uint32_t>(DepthRange::ZeroToOne) ==
                  static_cast<std::uint32_t>(TRISORT_DEPTH_RANGE_ZERO_TO_ONE),
              "DepthRange follows trisort.h");
static_assert(static_cast<std::uint32_t>(DepthRange::MinusOneToOne) ==
                  static_cast<std::uint32_t>(TRISORT_DEPTH_RANGE_MINUS_ONE_TO_ONE),
              "DepthRange follows trisort.h");

#if TRISORT_ABI_VERSION >= 5
/** A surface model, for Baked::gpu_lighting_uniform(): trisort.h's `TRISORT_SHADING_*`. */
enum class Shading : std::uint32_t {
    /** One light plus ambient, no tone map (what the exported GLSL ES shaders' basic path draws). */
    Basic = TRISORT_SHADING_BASIC,
    /** glTF metallic-roughness lit by the file's environment, tone mapped (the default). */
    Pbr = TRISORT_SHADING_PBR,
};

/** A tone map of the `Pbr` model: trisort.h's `TRISORT_TONE_MAP_*`. */
enum class ToneMap : std::uint32_t {
    /** Khronos PBR Neutral (the default). */
    Neutral = TRISORT_TONE_MAP_NEUTRAL,
    /** ACES (Narkowicz's fit). */
    Aces = TRISORT_TONE_MAP_ACES,
};

/** One of the two material texture arrays: trisort.h's `TRISORT_TEXTURE_ARRAY_*`. */
enum class TextureArray : std::uint32_t {
    /** Base colour and emissive textures, sRGB. */
    Srgb = TRISORT_TEXTURE_ARRAY_SRGB,
    /** Metallic-roughness, normal, occlusion and clearcoat textures, linear. */
    Linear = TRISORT_TEXTURE_ARRAY_LINEAR,
};
#endif

/**
 * A short English name of a status ("io", "out of range"...), for messages; "unknown status"
 * for a value this header does not know.
 */
inline const char *status_name(TrisortStatus status) noexcept {
    switch (static_cast<int>(status)) {
    case 0: return "ok";
    case 1: return "null argument";
    case 2: return "io";
    case 3: return "format";
    case 4: return "out of range";
    case 5: return "buffer too small";
    case 6: return "unsupported";
    case 7: return "panic";
    case 8: return "absent";
    case 9: return "profile mismatch";
    default: return "unknown status";
    }
}

/**
 * A failed call: the TrisortStatus the C API returned and its message (trisort_last_error(),
 * which names the file and the problem), as what().
 */
class Error : public std::runtime_error {
public:
    /** An error of `status` with `message` (what()). */
    Error(TrisortStatus status, const std::string &message)
        : std::runtime_error(message), status_(status) {}

    /**
     * The error of a call that just returned `status` on this thread: its message is
     * trisort_last_error()'s (or, should that be empty, "trisort: " and the status's name).
     */
    static Error last(TrisortStatus status) {
        std::size_t n = trisort_last_error(nullptr, 0);
        std::vector<char> buf(n + 1, '\0');
        n = trisort_last_error(buf.data(), buf.size());
        std::string message(buf.data(), n < buf.size() ? n : buf.size() - 1);
        if (message.empty()) {
            message = std::string("trisort: ") + status_name(status);
        }
        return Error(status, message);
    }

    /** The status the C API returned (never TRISORT_STATUS_OK). */
    TrisortStatus status() const noexcept { return status_; }

private:
    TrisortStatus status_;
};

#if defined(TRISORT_HPP_STD_EXPECTED)

using std::unexpect;
using std::unexpect_t;

/** A value of type T or the Error that prevented it: std::expected<T, trisort::Error>. */
template <class T>
using expected = std::expected<T, Error>;

#else

/** The tag that makes an expected hold an error: `expected<T>(trisort::unexpect, error)`. */
struct unexpect_t {
    explicit unexpect_t() = default;
};
/** The unexpect_t tag. */
inline constexpr unexpect_t unexpect{};

/**
 * Thrown (with exceptions enabled) by expected::value() on an expected that holds an error;
 * it is that Error. Without exceptions, value() on an error aborts instead.
 */
class bad_expected_access : public Error {
public:
    /** The access to `error`'s expected. */
    explicit bad_expected_access(const Error &error) : Error(error) {}
};

/**
 * A value of type T or the Error that prevented it: the subset of C++23's
 * `std::expected<T, trisort::Error>` that this wrapper needs, for C++17.
 */
template <class T>
class [[nodiscard]] expected {
public:
    /** The type of the value. */
    using value_type = T;
    /** The type of the error. */
    using error_type = Error;

    /** Holds `value`. */
    expected(const T &value) : v_(std::in_place_index<0>, value) {}
    /** Holds `value`. */
    expected(T &&value) : v_(std::in_place_index<0>, std::move(value)) {}
    /** Holds `error`. */
    expected(unexpect_t, Error error) : v_(std::in_place_index<1>, std::move(error)) {}

    /** Whether it holds a value (not an error). */
    bool has_value() const noexcept { return v_.index() == 0; }
    /** has_value(). */
    explicit operator bool() const noexcept { return has_value(); }

    /** The value; throws bad_expected_access (without exceptions: aborts) on an error. */
    T &value() & {
        check();
        return *std::get_if<0>(&v_);
    }
    /** The value; throws bad_expected_access (without exceptions: aborts) on an error. */
    const T &value() const & {
        check();
        return *std::get_if<0>(&v_);
    }
    /** The value, moved out; throws bad_expected_access (without exceptions: aborts). */
    T &&value() && {
        check();
        return std::move(*std::get_if<0>(&v_));
    }
    /** The value, or `fallback` on an error. */
    template <class U>
    T value_or(U &&fallback) const & {
        return has_value() ? *std::get_if<0>(&v_) : static_cast<T>(std::forward<U>(fallback));
    }
    /** The value (moved out), or `fallback` on an error. */
    template <class U>
    T value_or(U &&fallback) && {
        return has_value() ? std::move(*std::get_if<0>(&v_))
                           : static_cast<T>(std::forward<U>(fallback));
    }

    /** The error. Precondition: !has_value(). */
    const Error &error() const & noexcept { return *std::get_if<1>(&v_); }
    /** The error. Precondition: !has_value(). */
    Error &error() & noexcept { return *std::get_if<1>(&v_); }

    /** The value. Precondition: has_value(). */
    T &operator*() & noexcept { return *std::get_if<0>(&v_); }
    /** The value. Precondition: has_value(). */
    const T &operator*() const & noexcept { return *std::get_if<0>(&v_); }
    /** The value, moved out. Precondition: has_value(). */
    T &&operator*() && noexcept { return std::move(*std::get_if<0>(&v_)); }
    /** The value's members. Precondition: has_value(). */
    T *operator->() noexcept { return std::get_if<0>(&v_); }
    /** The value's members. Precondition: has_value(). */
    const T *operator->() const noexcept { return std::get_if<0>(&v_); }

private:
    void check() const {
        if (!has_value()) {
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
            throw bad_expected_access(error());
#else
            std::abort();
#endif
        }
    }

    std::variant<T, Error> v_;
};

#endif

#if defined(TRISORT_HPP_NO_EXCEPTIONS)
/** What a function that can fail returns: here trisort::expected<T>. */
template <class T>
using result = expected<T>;
#else
/** What a function that can fail returns: here T itself (failures throw trisort::Error). */
template <class T>
using result = T;
#endif

/** Pixels of an image: a texture level (RGBA8 bytes) or an environment level (binary16). */
template <class Texel>
struct Image {
    /** Width in texels. */
    std::uint32_t width = 0;
    /** Height in texels. */
    std::uint32_t height = 0;
    /** The texels, rows top to bottom, 4 values (RGBA) per texel. */
    std::vector<Texel> texels;
};

/** A texture level: RGBA8, sRGB or linear as its TrisortTextureInfo says. */
using TextureImage = Image<std::uint8_t>;
/** An environment level: RGBA as IEEE binary16 bits (upload as GL_RGBA16F, GL_HALF_FLOAT). */
using EnvironmentImage = Image<std::uint16_t>;

/** The outcome of Baked::check_device(). */
struct DeviceCheck {
    /** Whether nothing the host reported differs from the bake's raster profile. */
    bool matches = true;
    /** Every difference (the C API's message), empty when `matches`. */
    std::string differences;
};

#if TRISORT_ABI_VERSION >= 6
/**
 * A clip: one camera path of the file (Baked::clips()). It spans the file's frames
 * `first .. first + count - 1`; frame numbers elsewhere are the file's, so a host plays the
 * clip by drawing those frames.
 */
struct Clip {
    /** The clip's name ("main" for the only clip of a file baked from one unnamed path). */
    std::string name;
    /** Its first frame among the file's frames. */
    std::uint32_t first = 0;
    /** Its number of frames (at least 1). */
    std::uint32_t count = 0;
    /** The rate it plays at by default, or std::nullopt when the file stores none. */
    std::optional<double> fps;
};
#endif

/** The ABI version of the library actually linked (trisort_abi_version()). */
inline std::uint32_t abi_version() noexcept { return trisort_abi_version(); }

/**
 * Whether the linked library serves this header: its ABI version is at least the header's
 * TRISORT_ABI_VERSION (a library of a higher version only added to the lower ones).
 */
inline bool abi_compatible() noexcept { return trisort_abi_version() >= TRISORT_ABI_VERSION; }

#if TRISORT_ABI_VERSION >= 5
/** The baked-file format version the linked library reads (trisort_format_version()). */
inline std::uint32_t format_version() noexcept { return trisort_format_version(); }

/** The linked library's version, e.g. "0.1.0" (trisort_version_string(); static). */
inline const char *version_string() noexcept { return trisort_version_string(); }
#endif

/** Internals of the wrapper. */
namespace detail {

/** A failed call's result: throws, or returns the error as a result<T>. */
template <class T>
result<T> fail(TrisortStatus status) {
#if defined(TRISORT_HPP_NO_EXCEPTIONS)
    return result<T>(unexpect, Error::last(status));
#else
    throw Error::last(status);
#endif
}

/** The two-call copy convention: `call(out, cap, len)` once for the length, then the copy. */
template <class T, class Call>
result<std::vector<T>> copy(Call call) {
    std::size_t len = 0;
    TrisortStatus s = call(static_cast<T *>(nullptr), std::size_t{0}, &len);
    if (s != TRISORT_STATUS_OK) {
        return fail<std::vector<T>>(s);
    }
    std::vector<T> out(len);
    if (len > 0) {
        s = call(out.data(), out.size(), &len);
        if (s != TRISORT_STATUS_OK) {
            return fail<std::vector<T>>(s);
        }
        out.resize(len);
    }
    return out;
}

/** A NUL-terminated string copied out by `call(out, cap, len)`. */
template <class Call>
result<std::string> copy_string(Call call) {
    std::size_t len = 0;
    TrisortStatus s = call(static_cast<char *>(nullptr), std::size_t{0}, &len);
    if (s != TRISORT_STATUS_OK) {
        return fail<std::string>(s);
    }
    std::vector<char> buf(len + 1, '\0');
    s = call(buf.data(), buf.size(), &len);
    if (s != TRISORT_STATUS_OK) {
        return fail<std::string>(s);
    }
    return std::string(buf.data(), len);
}

/** One value stored by `call(&out)`. */
template <class T, class Call>
result<T> store(Call call) {
    T out{};
    TrisortStatus s = call(&out);
    if (s != TRISORT_STATUS_OK) {
        return fail<T>(s);
    }
    return out;
}

/** An image of `width`, `height` and texels copied out by `call(w, h, out, cap, len)`. */
template <class Texel, class Call>
result<Image<Texel>> image(Call call) {
    Image<Texel> img;
    std::size_t len = 0;
    TrisortStatus s = call(&img.width, &img.height, static_cast<Texel *>(nullptr),
                           std::size_t{0}, &len);
    if (s != TRISORT_STATUS_OK) {
        return fail<Image<Texel>>(s);
    }
    img.texels.resize(len);
    if (len > 0) {
        s = call(&img.width, &img.height, img.texels.data(), img.texels.size(), &len);
        if (s != TRISORT_STATUS_OK) {
            return fail<Image<Texel>>(s);
        }
        img.texels.resize(len);
    }
    return img;
}

/** The 16 floats stored by `call(out)`. */
template <class Call>
result<Matrix> matrix(Call call) {
    Matrix m{};
    TrisortStatus s = call(m.data());
    if (s != TRISORT_STATUS_OK) {
        return fail<Matrix>(s);
    }
    return m;
}

/** The type of parameter 4 (the depth range) of a trisort_frame_projection()-like function. */
template <class F>
struct depth_parameter;
template <class R, class H, class F, class A, class D, class O>
struct depth_parameter<R (*)(H, F, A, D, O)> {
    using type = D;
};

/**
 * `depth` as trisort_frame_projection()'s depth argument: the enum TrisortDepthRange of
 * ABI 4 and earlier, a uint32_t from ABI 5 on (the same values).
 */
inline typename depth_parameter<decltype(&trisort_frame_projection)>::type
depth_argument(DepthRange depth) noexcept {
    using D = typename depth_parameter<decltype(&trisort_frame_projection)>::type;
    return static_cast<D>(static_cast<std::uint32_t>(depth));
}

/** Closes a baked-file handle. */
struct CloseBaked {
    void operator()(TrisortBaked *h) const noexcept { trisort_close(h); }
};

/** Closes an ORDER-file handle. */
struct CloseOrder {
    void operator()(TrisortOrder *h) const noexcept { trisort_order_close(h); }
};

} // namespace detail

/**
 * A baked file, opened and kept in memory: its index buffer, draws, vertices, cameras,
 * materials, textures and light, each copied out on request. Move-only; the destructor
 * closes the handle.
 */
class Baked {
public:
    /** Takes ownership of `handle` (from trisort_open_*(); may be null: an empty Baked). */
    explicit Baked(TrisortBaked *handle) noexcept : h_(handle) {}

    /**
     * Opens the baked file at `path` (UTF-8): read, checked and kept in memory. A missing or
     * unreadable file fails with TRISORT_STATUS_IO, an invalid one with
     * TRISORT_STATUS_FORMAT; the message names the file.
     */
    static result<Baked> open(const std::string &path) {
        TrisortBaked *h = nullptr;
        TrisortStatus s = trisort_open_path(path.c_str(), &h);
        if (s != TRISORT_STATUS_OK) {
            return detail::fail<Baked>(s);
        }
        return Baked(h);
    }

    /** Opens a baked file from `size` bytes at `data` (copied: they may be freed after). */
    static result<Baked> from_bytes(const void *data, std::size_t size) {
        TrisortBaked *h = nullptr;
        TrisortStatus s = trisort_open_bytes(static_cast<const std::uint8_t *>(data), size, &h);
        if (s != TRISORT_STATUS_OK) {
            return detail::fail<Baked>(s);
        }
        return Baked(h);
    }

    /** Opens a baked file from the bytes of `bytes` (copied). */
    static result<Baked> from_bytes(const std::vector<std::uint8_t> &bytes) {
        return from_bytes(bytes.data(), bytes.size());
    }

#if defined(__cpp_lib_span) && __cpp_lib_span >= 202002L
    /** Opens a baked file from the bytes of `bytes` (copied). */
    static result<Baked> from_bytes(std::span<const std::uint8_t> bytes) {
        return from_bytes(bytes.data(), bytes.size());
    }
#endif

    /** The C handle (null when moved from), still owned by this object. */
    const TrisortBaked *get() const noexcept { return h_.get(); }

    /** Gives up ownership: returns the handle, which the caller must trisort_close(). */
    TrisortBaked *release() noexcept { return h_.release(); }

    /** The file's figures: frames, recorded size and samples, counts, recommended mode. */
    result<TrisortInfo> info() const {
        return detail::store<TrisortInfo>(
            [&](TrisortInfo *out) { return trisort_info(h_.get(), out); });
    }

    /**
     * The sorted index buffer as u32 indices into vertices(): front to back, or reversed
     * (`back_to_front`, what TRISORT_MODE_BLEND draws; use the same flag for frame_ranges()
     * and frame_draws()).
     */
    result<std::vector<std::uint32_t>> indices_u32(bool back_to_front = false) const {
        return detail::copy<std::uint32_t>([&](std::uint32_t *o, std::size_t c, std::size_t *l) {
            return trisort_indices_u32(h_.get(), back_to_front, o, c, l);
        });
    }

    /**
     * indices_u32() as u16 indices; fails with TRISORT_STATUS_UNSUPPORTED when the file has
     * more than 65,536 vertices (TrisortInfo::fits_u16).
     */
    result<std::vector<std::uint16_t>> indices_u16(bool back_to_front = false) const {
        return detail::copy<std::uint16_t>([&](std::uint16_t *o, std::size_t c, std::size_t *l) {
            return trisort_indices_u16(h_.get(), back_to_front, o, c, l);
        });
    }

    /** Frame `frame`'s draw ranges, in drawing order, over the index buffer of `back_to_front`. */
    result<std::vector<TrisortRange>> frame_ranges(std::uint32_t frame,
                                                   bool back_to_front = false) const {
        return detail::copy<TrisortRange>([&](TrisortRange *o, std::size_t c, std::size_t *l) {
            return trisort_frame_ranges(h_.get(), frame, back_to_front, o, c, l);
        });
    }

    /**
     * Frame `frame`'s draws as indexed indirect-draw arguments (the draws of frame_ranges(),
     * laid out for glMultiDrawElementsIndirect / vkCmdDrawIndexedIndirect).
     */
    result<std::vector<TrisortDrawIndexedIndirectArgs>>
    frame_draws(std::uint32_t frame, bool back_to_front = false) const {
        return detail::copy<TrisortDrawIndexedIndirectArgs>(
            [&](TrisortDrawIndexedIndirectArgs *o, std::size_t c, std::size_t *l) {
                return trisort_frame_draws(h_.get(), frame, back_to_front, o, c, l);
            });
    }

    /** The vertex streams, interleaved (64 bytes per vertex). */
    result<std::vector<TrisortVertex>> vertices() const {
        return detail::copy<TrisortVertex>([&](TrisortVertex *o, std::size_t c, std::size_t *l) {
            return trisort_vertices(h_.get(), o, c, l);
        });
    }

    /** Frame `frame`'s view matrix (world to view; right handed, looking down -Z). */
    result<Matrix> frame_view(std::uint32_t frame) const {
        return detail::matrix([&](float *out) { return trisort_frame_view(h_.get(), frame, out); });
    }

    /**
     * Frame `frame`'s projection matrix for an image of `aspect` (width / height) in the
     * clip-depth convention `depth`. A non-positive aspect fails with
     * TRISORT_STATUS_OUT_OF_RANGE.
     */
    result<Matrix> frame_projection(std::uint32_t frame, double aspect,
                                    DepthRange depth = DepthRange::ZeroToOne) const {
        return detail::matrix([&](float *out) {
            return trisort_frame_projection(h_.get(), frame, aspect,
                                            detail::depth_argument(depth), out);
        });
    }

    /**
     * Frame `frame`'s node matrices, one per node: with `view_relative` the camera-relative
     * view × world matrices (precise far from the origin), else the world matrices.
     */
    result<std::vector<Matrix>> frame_node_matrices(std::uint32_t frame,
                                                    bool view_relative = true) const {
        auto floats = detail::copy<float>([&](float *o, std::size_t c, std::size_t *l) {
            return trisort_frame_node_matrices(h_.get(), frame, view_relative, o, c, l);
        });
#if defined(TRISORT_HPP_NO_EXCEPTIONS)
        if (!floats) {
            return result<std::vector<Matrix>>(unexpect, floats.error());
        }
        const std::vector<float> &f = *floats;
#else
        const std::vector<float> &f = floats;
#endif
        std::vector<Matrix> out(f.size() / 16);
        for (std::size_t i = 0; i < out.size(); ++i) {
            for (std::size_t k = 0; k < 16; ++k) {
                out[i][k] = f[16 * i + k];
            }
        }
        return out;
    }

    /** The materials (the default ones; variant_materials() for a variant's). */
    result<std::vector<TrisortMaterial>> materials() const {
        return detail::copy<TrisortMaterial>(
            [&](TrisortMaterial *o, std::size_t c, std::size_t *l) {
                return trisort_materials(h_.get(), o, c, l);
            });
    }

    /** Texture `texture`'s size, colour space and mip level count. */
    result<TrisortTextureInfo> texture_info(std::uint32_t texture) const {
        return detail::store<TrisortTextureInfo>([&](TrisortTextureInfo *out) {
            return trisort_texture_info(h_.get(), texture, out);
        });
    }

    /** Texture `texture`'s level 0: RGBA8 texels, rows top to bottom. */
    result<TextureImage> texture(std::uint32_t texture) const {
        return detail::image<std::uint8_t>([&](std::uint32_t *w, std::uint32_t *h,
                                               std::uint8_t *o, std::size_t c, std::size_t *l) {
            return trisort_texture(h_.get(), texture, w, h, o, c, l);
        });
    }

    /** Mip level `level` of texture `texture` (levels run to its info's level_count). */
    result<TextureImage> texture_level(std::uint32_t texture, std::uint32_t level) const {
        return detail::image<std::uint8_t>([&](std::uint32_t *w, std::uint32_t *h,
                                               std::uint8_t *o, std::size_t c, std::size_t *l) {
            return trisort_texture_level(h_.get(), texture, level, w, h, o, c, l);
        });
    }

    /** The frame rate the path was recorded at, or std::nullopt when the file stores none. */
    result<std::optional<double>> fps() const {
        double out = 0.0;
        TrisortStatus s = trisort_fps(h_.get(), &out);
        if (s == TRISORT_STATUS_ABSENT) {
            return std::optional<double>();
        }
        if (s != TRISORT_STATUS_OK) {
            return detail::fail<std::optional<double>>(s);
        }
        return std::optional<double>(out);
    }

    /** The raster profile the bake assumes of the device that plays it. */
    result<TrisortRasterProfile> raster_profile() const {
        return detail::store<TrisortRasterProfile>(
            [&](TrisortRasterProfile *out) { return trisort_raster_profile(h_.get(), out); });
    }

    /**
     * Checks what the host's API reports about its device against the raster profile. A
     * device outside it is not an error: the result says so and names every difference (a
     * host refuses it or logs it); only a failed call (a null handle) is an error.
     */
    result<DeviceCheck> check_device(const TrisortDeviceRaster &device) const {
        TrisortStatus s = trisort_check_device(h_.get(), &device);
        if (s == TRISORT_STATUS_OK) {
            return DeviceCheck{true, std::string()};
        }
        if (s == TRISORT_STATUS_PROFILE_MISMATCH) {
            return DeviceCheck{false, Error::last(s).what()};
        }
        return detail::fail<DeviceCheck>(s);
    }

    /** The figures of the light the file is shaded with (SH irradiance, sun, exposure). */
    result<TrisortEnvironmentInfo> environment_info() const {
        return detail::store<TrisortEnvironmentInfo>([&](TrisortEnvironmentInfo *out) {
            return trisort_environment_info(h_.get(), out);
        });
    }

    /** The environment's name ("studio" for the built-in light, else the HDR file's name). */
    result<std::string> environment_name() const {
        return detail::copy_string([&](char *o, std::size_t c, std::size_t *l) {
            return trisort_environment_name(h_.get(), o, c, l);
        });
    }

    /** Prefiltered level `level` of the environment (equirectangular, rows from the zenith). */
    result<EnvironmentImage> environment_level(std::uint32_t level) const {
        return detail::image<std::uint16_t>([&](std::uint32_t *w, std::uint32_t *h,
                                                std::uint16_t *o, std::size_t c,
                                                std::size_t *l) {
            return trisort_environment_level(h_.get(), level, w, h, o, c, l);
        });
    }

    /** The number of material variants (KHR_materials_variants; 0 without). */
    result<std::uint32_t> variant_count() const {
        return detail::store<std::uint32_t>(
            [&](std::uint32_t *out) { return trisort_variant_count(h_.get(), out); });
    }

    /** The name of material variant `variant` (may be empty; need not be unique). */
    result<std::string> variant_name(std::uint32_t variant) const {
        return detail::copy_string([&](char *o, std::size_t c, std::size_t *l) {
            return trisort_variant_name(h_.get(), variant, o, c, l);
        });
    }

    /** The names of all material variants, in file order. */
    result<std::vector<std::string>> variant_names() const {
        std::uint32_t n = 0;
        TrisortStatus s = trisort_variant_count(h_.get(), &n);
        if (s != TRISORT_STATUS_OK) {
            return detail::fail<std::vector<std::string>>(s);
        }
        std::vector<std::string> names;
        for (std::uint32_t v = 0; v < n; ++v) {
            auto name = variant_name(v);
#if defined(TRISORT_HPP_NO_EXCEPTIONS)
            if (!name) {
                return result<std::vector<std::string>>(unexpect, name.error());
            }
            names.push_back(std::move(*name));
#else
            names.push_back(std::move(name));
#endif
        }
        return names;
    }

    /**
     * The material table under the variant named `name`: entry k is what material slot k
     * shows. Fails with TRISORT_STATUS_ABSENT for an unknown name, TRISORT_STATUS_UNSUPPORTED
     * for a variant that changes visibility (the bake would not be exact for it).
     */
    result<std::vector<TrisortMaterial>> variant_materials(const std::string &name) const {
        return detail::copy<TrisortMaterial>(
            [&](TrisortMaterial *o, std::size_t c, std::size_t *l) {
                return trisort_variant_materials(h_.get(), name.c_str(), o, c, l);
            });
    }

#if TRISORT_ABI_VERSION >= 5
    // What the player uploads, for a host drawing with `trisort export-shaders`' shaders
    // (trisort.h's trisort_gpu_*; `max_texture_size` is the device's largest 2D texture,
    // 0 for no limit).

    /**
     * Frame `frame`'s `Frame` uniform for an image of `width` × `height` (0, 0: the recorded
     * size): TRISORT_GPU_FRAME_UNIFORM_SIZE bytes, std140.
     */
    result<std::vector<std::uint8_t>> gpu_frame_uniform(std::uint32_t frame,
                                                        std::uint32_t width = 0,
                                                        std::uint32_t height = 0) const {
        return detail::copy<std::uint8_t>([&](std::uint8_t *o, std::size_t c, std::size_t *l) {
            return trisort_gpu_frame_uniform(h_.get(), frame, width, height, o, c, l);
        });
    }

    /** The `Lighting` uniform: TRISORT_GPU_LIGHTING_UNIFORM_SIZE bytes, std140. */
    result<std::vector<std::uint8_t>> gpu_lighting_uniform(Shading shading = Shading::Pbr,
                                                           ToneMap tone_map = ToneMap::Neutral,
                                                           std::uint32_t max_texture_size = 0) const {
        return detail::copy<std::uint8_t>([&](std::uint8_t *o, std::size_t c, std::size_t *l) {
            return trisort_gpu_lighting_uniform(h_.get(), static_cast<std::uint32_t>(shading),
                                                static_cast<std::uint32_t>(tone_map),
                                                max_texture_size, o, c, l);
        });
    }

    /**
     * The material data texture's texels: RGBA32F, TRISORT_GPU_DATA_WIDTH texels a row
     * (upload as TRISORT_GPU_DATA_WIDTH × size() / 4 / TRISORT_GPU_DATA_WIDTH).
     */
    result<std::vector<float>> gpu_material_texels(std::uint32_t max_texture_size = 0) const {
        return detail::copy<float>([&](float *o, std::size_t c, std::size_t *l) {
            return trisort_gpu_material_texels(h_.get(), max_texture_size, o, c, l);
        });
    }

    /** The node data texture's texels: every frame's node matrices, RGBA32F, as above. */
    result<std::vector<float>> gpu_node_texels() const {
        return detail::copy<float>([&](float *o, std::size_t c, std::size_t *l) {
            return trisort_gpu_node_texels(h_.get(), o, c, l);
        });
    }

    /** The size of material texture array `array` as the player uploads it. */
    result<TrisortGpuTexture> gpu_texture_array(TextureArray array,
                                                std::uint32_t max_texture_size = 0) const {
        return detail::store<TrisortGpuTexture>([&](TrisortGpuTexture *out) {
            return trisort_gpu_texture_array(h_.get(), static_cast<std::uint32_t>(array),
                                             max_texture_size, out);
        });
    }

    /** Level `level` of layer `layer` of texture array `array`: RGBA8, rows top to bottom. */
    result<std::vector<std::uint8_t>> gpu_texture_array_level(TextureArray array,
                                                              std::uint32_t layer,
                                                              std::uint32_t level,
                                                              std::uint32_t max_texture_size = 0) const {
        return detail::copy<std::uint8_t>([&](std::uint8_t *o, std::size_t c, std::size_t *l) {
            return trisort_gpu_texture_array_level(h_.get(), static_cast<std::uint32_t>(array),
                                                   layer, level, max_texture_size, o, c, l);
        });
    }

    /** The size of the prefiltered environment as the player uploads it (`layers` 1). */
    result<TrisortGpuTexture> gpu_environment(std::uint32_t max_texture_size = 0) const {
        return detail::store<TrisortGpuTexture>([&](TrisortGpuTexture *out) {
            return trisort_gpu_environment(h_.get(), max_texture_size, out);
        });
    }

    /** Level `level` of that environment: RGBA binary16 bits (GL_RGBA16F, GL_HALF_FLOAT). */
    result<std::vector<std::uint16_t>> gpu_environment_level(std::uint32_t level,
                                                             std::uint32_t max_texture_size = 0) const {
        return detail::copy<std::uint16_t>([&](std::uint16_t *o, std::size_t c, std::size_t *l) {
            return trisort_gpu_environment_level(h_.get(), level, max_texture_size, o, c, l);
        });
    }
#endif

#if TRISORT_ABI_VERSION >= 6
    /** The file's clips (at least one), in file order: together they cover its frames. */
    result<std::vector<Clip>> clips() const {
        std::uint32_t n = 0;
        TrisortStatus s = trisort_clip_count(h_.get(), &n);
        if (s != TRISORT_STATUS_OK) {
            return detail::fail<std::vector<Clip>>(s);
        }
        std::vector<Clip> clips(n);
        for (std::uint32_t k = 0; k < n; ++k) {
            Clip &c = clips[k];
            auto name = detail::copy_string([&](char *o, std::size_t cap, std::size_t *l) {
                return trisort_clip_name(h_.get(), k, o, cap, l);
            });
#if defined(TRISORT_HPP_NO_EXCEPTIONS)
            if (!name) {
                return result<std::vector<Clip>>(unexpect, name.error());
            }
            c.name = std::move(*name);
#else
            c.name = std::move(name);
#endif
            s = trisort_clip_frames(h_.get(), k, &c.first, &c.count);
            if (s != TRISORT_STATUS_OK) {
                return detail::fail<std::vector<Clip>>(s);
            }
            double fps = 0.0;
            s = trisort_clip_fps(h_.get(), k, &fps);
            if (s == TRISORT_STATUS_OK) {
                c.fps = fps;
            } else if (s != TRISORT_STATUS_ABSENT) {
                return detail::fail<std::vector<Clip>>(s);
            }
        }
        return clips;
    }

    /**
     * The index of the clip named `name` (for clips()). Fails with TRISORT_STATUS_ABSENT when
     * no clip has the name; the message lists the file's clips.
     */
    result<std::uint32_t> find_clip(const std::string &name) const {
        return detail::store<std::uint32_t>([&](std::uint32_t *out) {
            return trisort_clip_find(h_.get(), name.c_str(), out);
        });
    }
#endif

private:
    std::unique_ptr<TrisortBaked, detail::CloseBaked> h_;
};

/**
 * An ORDER file (the order-only export: each index-buffer triangle's glTF source and each
 * frame's ranges), opened and kept in memory. Move-only; the destructor closes the handle.
 */
class Order {
public:
    /** Takes ownership of `handle` (from trisort_order_open_*(); may be null). */
    explicit Order(TrisortOrder *handle) noexcept : h_(handle) {}

    /** Opens the ORDER file at `path` (UTF-8); the message of a failure names the file. */
    static result<Order> open(const std::string &path) {
        TrisortOrder *h = nullptr;
        TrisortStatus s = trisort_order_open_path(path.c_str(), &h);
        if (s != TRISORT_STATUS_OK) {
            return detail::fail<Order>(s);
        }
        return Order(h);
    }

    /** Opens an ORDER file from `size` bytes at `data` (copied). */
    static result<Order> from_bytes(const void *data, std::size_t size) {
        TrisortOrder *h = nullptr;
        TrisortStatus s =
            trisort_order_open_bytes(static_cast<const std::uint8_t *>(data), size, &h);
        if (s != TRISORT_STATUS_OK) {
            return detail::fail<Order>(s);
        }
        return Order(h);
    }

    /** Opens an ORDER file from the bytes of `bytes` (copied). */
    static result<Order> from_bytes(const std::vector<std::uint8_t> &bytes) {
        return from_bytes(bytes.data(), bytes.size());
    }

#if defined(__cpp_lib_span) && __cpp_lib_span >= 202002L
    /** Opens an ORDER file from the bytes of `bytes` (copied). */
    static result<Order> from_bytes(std::span<const std::uint8_t> bytes) {
        return from_bytes(bytes.data(), bytes.size());
    }
#endif

    /** The C handle (null when moved from), still owned by this object. */
    const TrisortOrder *get() const noexcept { return h_.get(); }

    /** Gives up ownership: returns the handle, which the caller must trisort_order_close(). */
    TrisortOrder *release() noexcept { return h_.release(); }

    /** The file's figures: frames, ranges, triangles, whether the bake split triangles. */
    result<TrisortOrderInfo> info() const {
        return detail::store<TrisortOrderInfo>(
            [&](TrisortOrderInfo *out) { return trisort_order_info(h_.get(), out); });
    }

    /** Frame `frame`'s ranges (first triangle, triangle count), front to back. */
    result<std::vector<TrisortOrderRange>> frame_ranges(std::uint32_t frame) const {
        return detail::copy<TrisortOrderRange>(
            [&](TrisortOrderRange *o, std::size_t c, std::size_t *l) {
                return trisort_order_frame_ranges(h_.get(), frame, o, c, l);
            });
    }

    /** Every index-buffer triangle's source (mesh, primitive, triangle, node), front to back. */
    result<std::vector<TrisortOrderSource>> triangles() const {
        return detail::copy<TrisortOrderSource>(
            [&](TrisortOrderSource *o, std::size_t c, std::size_t *l) {
                return trisort_order_triangles(h_.get(), o, c, l);
            });
    }

private:
    std::unique_ptr<TrisortOrder, detail::CloseOrder> h_;
};

} // namespace trisort

#endif /* TRISORT_HPP */
