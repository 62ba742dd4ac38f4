// trisort.hpp in use: opens the baked file named on the command line, prints its figures,
// copies one frame's draws and indices (back to front, as blending draws them) and its
// matrices, and shows what a failure looks like (opening a file that is not there).
//
// Built twice from this one file: as is, trisort.hpp throws trisort::Error; with
// -DTRISORT_HPP_NO_EXCEPTIONS its functions return trisort::expected<T> instead (collect()
// below is written once per mode). Both print the same report, as `key: value` lines.
//
//   example BAKED [FRAME]      exit status 0, or 1 with a message on stderr
#include <trisort.hpp>

#include <cstdint>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace {

// Everything the report prints, copied out of the file.
struct Report {
    TrisortInfo info{};
    std::optional<double> fps;
    std::string environment_name;
    TrisortEnvironmentInfo environment{};
    std::vector<std::string> variants;
    TrisortRasterProfile profile{};
    trisort::DeviceCheck device;
    std::size_t vertex_count = 0;
    std::size_t material_count = 0;
    std::uint32_t frame = 0;
    std::vector<std::uint32_t> indices;  // back to front
    bool u16_equal = false;              // the u16 buffer equals the u32 one (when it fits)
    std::vector<TrisortDrawIndexedIndirectArgs> draws;
    std::vector<TrisortRange> ranges;
    trisort::Matrix view{};
    trisort::Matrix projection_zero_to_one{};
    trisort::Matrix projection_minus_one_to_one{};
    std::size_t node_matrix_count = 0;
    // What the player uploads (for a host drawing with `trisort export-shaders`' shaders).
    std::vector<std::uint8_t> gpu_frame_uniform;     // frame `frame`, at the recorded size
    std::vector<std::uint8_t> gpu_lighting_uniform;  // PBR, neutral tone map
    std::size_t gpu_material_floats = 0;
    std::size_t gpu_node_floats = 0;
    TrisortGpuTexture gpu_srgb{};
    std::vector<std::uint8_t> gpu_srgb_level0;  // layer 0
    TrisortGpuTexture gpu_environment{};
    std::size_t gpu_environment_level0 = 0;     // binary16 values
#if TRISORT_ABI_VERSION >= 6
    std::vector<trisort::Clip> clips;
    std::uint32_t last_clip_found = 0;  // find_clip() of the last clip's name
#endif
};

// A device as a host's graphics API might describe it: 8 sub-pixel bits, the standard
// sample locations, the recorded sample count.
TrisortDeviceRaster device_of(const TrisortInfo &info) {
    TrisortDeviceRaster d{};
    d.subpixel_bits = 8;
    d.standard_sample_locations = 1;
    d.samples = info.samples;
    return d;
}

bool same_indices(const std::vector<std::uint16_t> &a, const std::vector<std::uint32_t> &b) {
    if (a.size() != b.size()) {
        return false;
    }
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (a[i] != b[i]) {
            return false;
        }
    }
    return true;
}

#if !defined(TRISORT_HPP_NO_EXCEPTIONS)

const char *const mode = "exceptions";

// Every call either returns its value or throws trisort::Error.
Report collect(const std::string &path, std::uint32_t frame) {
    trisort::Baked baked = trisort::Baked::open(path);
    Report r;
    r.info = baked.info();
    r.fps = baked.fps();
    r.environment_name = baked.environment_name();
    r.environment = baked.environment_info();
    r.variants = baked.variant_names();
    r.profile = baked.raster_profile();
    r.device = baked.check_device(device_of(r.info));
    r.vertex_count = baked.vertices().size();
    r.material_count = baked.materials().size();
    r.frame = frame;
    r.indices = baked.indices_u32(true);
    if (r.info.fits_u16) {
        r.u16_equal = same_indices(baked.indices_u16(true), r.indices);
    }
    r.draws = baked.frame_draws(frame, true);
    r.ranges = baked.frame_ranges(frame, true);
    const double aspect = double(r.info.width) / double(r.info.height);
    r.view = baked.frame_view(frame);
    r.projection_zero_to_one =
        baked.frame_projection(frame, aspect, trisort::DepthRange::ZeroToOne);
    r.projection_minus_one_to_one =
        baked.frame_projection(frame, aspect, trisort::DepthRange::MinusOneToOne);
    r.node_matrix_count = baked.frame_node_matrices(frame, true).size();
    r.gpu_frame_uniform = baked.gpu_frame_uniform(frame);
    r.gpu_lighting_uniform = baked.gpu_lighting_uniform(trisort::Shading::Pbr);
    r.gpu_material_floats = baked.gpu_material_texels().size();
    r.gpu_node_floats = baked.gpu_node_texels().size();
    r.gpu_srgb = baked.gpu_texture_array(trisort::TextureArray::Srgb);
    r.gpu_srgb_level0 = baked.gpu_texture_array_level(trisort::TextureArray::Srgb, 0, 0);
    r.gpu_environment = baked.gpu_environment();
    r.gpu_environment_level0 = baked.gpu_environment_level(0).size();
#if TRISORT_ABI_VERSION >= 6
    r.clips = baked.clips();
    r.last_clip_found = baked.find_clip(r.clips.back().name);
#endif
    return r;
}

// The message a failure to open `path` gives.
std::string open_failure(const std::string &path) {
    try {
        trisort::Baked::open(path);
        return "(opened?)";
    } catch (const trisort::Error &e) {
        return std::string(trisort::status_name(e.status())) + ": " + e.what();
    }
}

#else

const char *const mode = "expected";

// Returns the error of `expr` (a trisort::expected) from collect(), else names its value.
#define EXAMPLE_TRY(name, expr)                                                                \
    auto name = (expr);                                                                        \
    if (!name) {                                                                               \
        return trisort::expected<Report>(trisort::unexpect, name.error());                     \
    }

// Every call returns a trisort::expected: the value, or the error that prevented it.
trisort::expected<Report> collect(const std::string &path, std::uint32_t frame) {
    trisort::expected<trisort::Baked> opened = trisort::Baked::open(path);
    if (!opened) {
        return trisort::expected<Report>(trisort::unexpect, opened.error());
    }
    const trisort::Baked &baked = *opened;
    Report r;
    EXAMPLE_TRY(info, baked.info());
    r.info = *info;
    EXAMPLE_TRY(fps, baked.fps());
    r.fps = *fps;
    EXAMPLE_TRY(environment_name, baked.environment_name());
    r.environment_name = *environment_name;
    EXAMPLE_TRY(environment, baked.environment_info());
    r.environment = *environment;
    EXAMPLE_TRY(variants, baked.variant_names());
    r.variants = *variants;
    EXAMPLE_TRY(profile, baked.raster_profile());
    r.profile = *profile;
    EXAMPLE_TRY(device, baked.check_device(device_of(r.info)));
    r.device = *device;
    EXAMPLE_TRY(vertices, baked.vertices());
    r.vertex_count = vertices->size();
    EXAMPLE_TRY(materials, baked.materials());
    r.material_count = materials->size();
    r.frame = frame;
    EXAMPLE_TRY(indices, baked.indices_u32(true));
    r.indices = std::move(*indices);
    if (r.info.fits_u16) {
        EXAMPLE_TRY(indices16, baked.indices_u16(true));
        r.u16_equal = same_indices(*indices16, r.indices);
    }
    EXAMPLE_TRY(draws, baked.frame_draws(frame, true));
    r.draws = *draws;
    EXAMPLE_TRY(ranges, baked.frame_ranges(frame, true));
    r.ranges = *ranges;
    const double aspect = double(r.info.width) / double(r.info.height);
    EXAMPLE_TRY(view, baked.frame_view(frame));
    r.view = *view;
    EXAMPLE_TRY(zero_to_one, baked.frame_projection(frame, aspect, trisort::DepthRange::ZeroToOne));
    r.projection_zero_to_one = *zero_to_one;
    EXAMPLE_TRY(minus_one_to_one,
                baked.frame_projection(frame, aspect, trisort::DepthRange::MinusOneToOne));
    r.projection_minus_one_to_one = *minus_one_to_one;
    EXAMPLE_TRY(nodes, baked.frame_node_matrices(frame, true));
    r.node_matrix_count = nodes->size();
    EXAMPLE_TRY(frame_uniform, baked.gpu_frame_uniform(frame));
    r.gpu_frame_uniform = *frame_uniform;
    EXAMPLE_TRY(lighting, baked.gpu_lighting_uniform(trisort::Shading::Pbr));
    r.gpu_lighting_uniform = *lighting;
    EXAMPLE_TRY(material_texels, baked.gpu_material_texels());
    r.gpu_material_floats = material_texels->size();
    EXAMPLE_TRY(node_texels, baked.gpu_node_texels());
    r.gpu_node_floats = node_texels->size();
    EXAMPLE_TRY(srgb, baked.gpu_texture_array(trisort::TextureArray::Srgb));
    r.gpu_srgb = *srgb;
    EXAMPLE_TRY(srgb_level0, baked.gpu_texture_array_level(trisort::TextureArray::Srgb, 0, 0));
    r.gpu_srgb_level0 = *srgb_level0;
    EXAMPLE_TRY(gpu_environment, baked.gpu_environment());
    r.gpu_environment = *gpu_environment;
    EXAMPLE_TRY(environment_level0, baked.gpu_environment_level(0));
    r.gpu_environment_level0 = environment_level0->size();
#if TRISORT_ABI_VERSION >= 6
    EXAMPLE_TRY(clips, baked.clips());
    r.clips = std::move(*clips);
    EXAMPLE_TRY(found, baked.find_clip(r.clips.back().name));
    r.last_clip_found = *found;
#endif
    return r;
}

std::string open_failure(const std::string &path) {
    trisort::expected<trisort::Baked> baked = trisort::Baked::open(path);
    if (baked) {
        return "(opened?)";
    }
    return std::string(trisort::status_name(baked.error().status())) + ": " +
           baked.error().what();
}

#endif

void print_matrix(const char *name, const trisort::Matrix &m) {
    std::cout << name << ":";
    for (float v : m) {
        std::cout << ' ' << std::setprecision(9) << v;
    }
    std::cout << '\n';
}

// Prints the report; false when the frame's draws do not fit the index buffer or differ from
// its ranges (which would be a bug).
bool print(const std::string &path, const Report &r) {
    const TrisortInfo &i = r.info;
    std::cout << "mode: " << mode << '\n';
    std::cout << "abi: library " << trisort::abi_version() << ", header " << TRISORT_ABI_VERSION
              << (trisort::abi_compatible() ? "" : " (the library is older than the header)")
              << '\n';
#if TRISORT_ABI_VERSION >= 5
    std::cout << "library version: " << trisort::version_string() << ", reads format "
              << trisort::format_version() << '\n';
#endif
    std::cout << "file: " << path << '\n';
    std::cout << "frames: " << i.frame_count << '\n';
    std::cout << "image: " << i.width << 'x' << i.height << ", " << i.samples << " samples\n";
    std::cout << "vertices: " << i.vertex_count << " (copied " << r.vertex_count << ")\n";
    std::cout << "triangles: " << i.triangle_count << '\n';
    std::cout << "index triangles: " << i.index_triangle_count << '\n';
    std::cout << "draws: " << i.draw_count << '\n';
    std::cout << "nodes: " << i.node_count << '\n';
    std::cout << "materials: " << i.material_count << " (copied " << r.material_count << ")\n";
    std::cout << "textures: " << i.texture_count << '\n';
    std::cout << "fits u16: " << (i.fits_u16 ? "yes" : "no") << '\n';
    std::cout << "recommended mode: " << static_cast<unsigned>(i.recommended_mode) << '\n';
    if (r.fps) {
        std::cout << "fps: " << std::setprecision(17) << *r.fps << '\n';
    } else {
        std::cout << "fps: none\n";
    }
    std::cout << "environment: " << r.environment_name << ", " << r.environment.width << 'x'
              << r.environment.height << ", " << r.environment.level_count << " levels\n";
    std::cout << "variants: " << r.variants.size();
    for (const std::string &v : r.variants) {
        std::cout << " '" << v << "'";
    }
    std::cout << '\n';
    std::cout << "raster profile: " << r.profile.name << ", subpixel bits "
              << r.profile.subpixel_bits_min << ".." << r.profile.subpixel_bits_max << '\n';
    std::cout << "device check: "
              << (r.device.matches ? std::string("matches") : r.device.differences) << '\n';

    std::uint64_t sum = 0;
    std::uint64_t count = 0;
    bool ok = r.ranges.size() == r.draws.size();
    for (std::size_t k = 0; k < r.draws.size(); ++k) {
        const TrisortDrawIndexedIndirectArgs &d = r.draws[k];
        if (std::uint64_t(d.first_index) + d.index_count > r.indices.size()) {
            std::cerr << "error: draw " << k << " reaches past the index buffer\n";
            return false;
        }
        ok = ok && r.ranges[k].first == d.first_index && r.ranges[k].count == d.index_count;
        for (std::uint32_t n = 0; n < d.index_count; ++n) {
            sum += r.indices[d.first_index + n];
        }
        count += d.index_count;
    }
    std::cout << "index buffer: " << r.indices.size() << " indices\n";
    std::cout << "u16 indices equal: " << (i.fits_u16 ? (r.u16_equal ? "yes" : "no") : "n/a")
              << '\n';
    std::cout << "frame: " << r.frame << '\n';
    std::cout << "frame draws: " << r.draws.size() << '\n';
    if (!r.draws.empty()) {
        std::cout << "first draw: " << r.draws[0].first_index << ' ' << r.draws[0].index_count
                  << '\n';
    }
    std::cout << "frame indices: " << count << '\n';
    std::cout << "frame index sum: " << sum << '\n';
    std::cout << "frame ranges equal draws: " << (ok ? "yes" : "no") << '\n';
    print_matrix("view", r.view);
    print_matrix("projection zero to one", r.projection_zero_to_one);
    print_matrix("projection minus one to one", r.projection_minus_one_to_one);
    std::cout << "node matrices: " << r.node_matrix_count << '\n';
    const auto byte_sum = [](const std::vector<std::uint8_t> &v) {
        std::uint64_t total = 0;
        for (std::uint8_t b : v) {
            total += b;
        }
        return total;
    };
    std::cout << "gpu frame uniform: " << r.gpu_frame_uniform.size() << " bytes, sum "
              << byte_sum(r.gpu_frame_uniform) << '\n';
    std::cout << "gpu lighting uniform: " << r.gpu_lighting_uniform.size() << " bytes, sum "
              << byte_sum(r.gpu_lighting_uniform) << '\n';
    std::cout << "gpu texels: " << r.gpu_material_floats << " material floats, "
              << r.gpu_node_floats << " node floats\n";
    std::cout << "gpu srgb array: " << r.gpu_srgb.width << 'x' << r.gpu_srgb.height << ", "
              << r.gpu_srgb.layers << " layers, " << r.gpu_srgb.levels << " levels; level 0: "
              << r.gpu_srgb_level0.size() << " bytes, sum " << byte_sum(r.gpu_srgb_level0) << '\n';
    std::cout << "gpu environment: " << r.gpu_environment.width << 'x'
              << r.gpu_environment.height << ", " << r.gpu_environment.levels
              << " levels; level 0: " << r.gpu_environment_level0 << " halves\n";
#if TRISORT_ABI_VERSION >= 6
    // A clip plays the file's frames first .. first + count - 1.
    std::cout << "clips: " << r.clips.size();
    for (const trisort::Clip &c : r.clips) {
        std::cout << " '" << c.name << "' " << c.first << '+' << c.count << " @";
        if (c.fps) {
            std::cout << std::setprecision(17) << *c.fps;
        } else {
            std::cout << "none";
        }
    }
    std::cout << '\n';
    std::cout << "last clip found: " << r.last_clip_found << '\n';
#endif
    return ok;
}

} // namespace

int main(int argc, char **argv) {
    if (argc < 2 || argc > 3) {
        std::cerr << "usage: " << argv[0] << " BAKED [FRAME]\n";
        return 2;
    }
    const std::string path = argv[1];
    const std::uint32_t frame =
        argc == 3 ? static_cast<std::uint32_t>(std::strtoul(argv[2], nullptr, 10)) : 0;

#if !defined(TRISORT_HPP_NO_EXCEPTIONS)
    Report report;
    try {
        report = collect(path, frame);
    } catch (const trisort::Error &e) {
        std::cerr << "error (" << trisort::status_name(e.status()) << "): " << e.what() << '\n';
        return 1;
    }
#else
    trisort::expected<Report> collected = collect(path, frame);
    if (!collected) {
        const trisort::Error &e = collected.error();
        std::cerr << "error (" << trisort::status_name(e.status()) << "): " << e.what() << '\n';
        return 1;
    }
    const Report &report = *collected;
#endif
    if (!print(path, report)) {
        return 1;
    }
    // A failure on purpose: the message names the file and what went wrong.
    std::cout << "missing file: " << open_failure(path + ".missing") << '\n';
    return 0;
}
