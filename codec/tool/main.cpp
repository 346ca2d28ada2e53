// pomar: command-line front end of the codec. The command table (CLI11: every command's
// arguments, options and help) and main(), which runs the command and maps a pomar::Error
// to the exit status (exit_codes.h).
//   pomar encode IN OUT.pomar [--bits N] [--progressive] [--strict | --repair] [--keep-order]
//                [--no-stored-errors] [--block-order spatial|id] [--max-memory SIZE]
//   pomar decode IN.pomar OUT [--level L] [--cluster/--sphere/--box ...] [--skip-damaged]
//                [--max-memory SIZE]
//   pomar info IN.pomar [--json | --check]
//   pomar verify ORIGINAL IN.pomar [DECODED] [--repair]
#include <CLI/CLI.hpp>

#include <csignal>
#include <cstdio>
#include <exception>

#include "commands.h"
#include "exit_codes.h"
#include "pomar/mesh_io.h"
#include "pomar/pomar.h"

namespace pomar::tool {
namespace {

CLI::App *add_encode_command(CLI::App &app, EncodeArgs &a) {
  CLI::App *enc =
      app.add_subcommand("encode", "Compress a mesh (PLY, OBJ, OFF, STL) into a .pomar file");
  enc->add_option("input", a.in,
                  "Input mesh, any triangles: a non-manifold or inconsistently oriented mesh, "
                  "duplicate faces, faces repeating a vertex and unreferenced vertices are coded "
                  "as a manifold cut plus a record that a full decode undoes (one line on stderr "
                  "says what was stored)")
      ->required();
  enc->add_option("output", a.out, "Output .pomar file (written atomically)")->required();
  enc->add_option("-b,--bits", a.bits,
                  "Quantization bits per coordinate on the bounding box (4..24); the geometry "
                  "error is at most half a cell")
      ->check(CLI::Range(4, 24))
      ->capture_default_str();
  enc->add_option("--clusters", a.clusters,
                  "Random access: about N clusters (regions decodable on their own)")
      ->check(CLI::PositiveNumber);
  enc->add_option("--cluster-ratio", a.cluster_ratio,
                  "Random access: clusters as a fraction of the vertices (paper: 1-5%)")
      ->check(CLI::Range(0.0001, 1.0))
      ->capture_default_str();
  enc->add_flag("--progressive", a.progressive,
                "Pure progressive mode: global levels only, no random access (a little smaller)");
  enc->add_flag("--no-stored-errors", a.no_stored_errors,
                "Random access: leave out the geometric error stored per cluster and level (about "
                "3% of the file); view-dependent decoding (the web viewer) then estimates the "
                "errors from edge lengths");
  enc->add_option("--block-order", a.block_order,
                  "Random access: how the cluster blocks are laid out in the file: spatial (the "
                  "Morton order of the clusters, so that the blocks of one region lie together: "
                  "fewer, longer byte ranges to fetch) or id (cluster id order)")
      ->check(CLI::IsMember({"spatial", "id"}))
      ->capture_default_str();
  enc->add_option("--threads", a.threads,
                  "Threads for decimation (0 = every core this process may use); the output is the "
                  "same for any number")
      ->capture_default_str();
  enc->add_flag("--repair", a.repair,
                "Opt-in: first cut a non-manifold, inconsistently oriented or degenerate mesh into "
                "a manifold one (remove faces repeating a vertex and exact duplicate faces, "
                "reorient faces, cut edges of more than two faces or that cannot be oriented, "
                "split vertices joining several fans into copies at the same position) and print "
                "every change on stderr. Positions are never moved; the file holds the repaired "
                "mesh (verify with --repair)");
  enc->add_flag("--strict", a.strict,
                "Refuse a mesh that needs cutting (non-manifold, inconsistently oriented, "
                "duplicate or degenerate faces) and drop unreferenced vertices: for pipelines "
                "that want clean input (the file then carries no lossless record)");
  enc->add_flag("--keep-order", a.keep_order,
                "Also store the input's vertex numbering (a full decode gives the vertices back "
                "in the input order, e.g. for per-vertex data kept elsewhere); costs a few bits "
                "per vertex (pomar info shows it as the lossless record)");
  enc->add_flag("--embed-textures", a.embed_textures,
                "Store the texture image files (found beside the input, by the names its "
                "materials or header give) in the .pomar, so that one file is the whole asset; "
                "decode writes them beside its output (never over an existing file). Without "
                "it, the names are kept and resolved relative to the file");
  enc->add_flag("--force", a.force,
                "Write the .pomar file even under a mesh file's extension (.ply .obj .off "
                ".stl), which is otherwise refused (an output that is the input is always "
                "refused)");
  enc->add_flag("-q,--quiet", a.quiet,
                "Print nothing on success (what --repair changed is still printed)");
  enc->add_option("--drop", a.drop,
                  "Per-vertex attributes to leave out, comma-separated: colour, normals, "
                  "scalars (quality and named PLY properties), texcoords (with the texture file "
                  "names), or all. Default: everything the input has is kept")
      ->type_name("LIST");
  enc->add_option("--normal-bits", a.attributes.normal_bits,
                  "Bits per octahedral coordinate of normals (4..16); the angle error is at most "
                  "0.332 deg at 9, halved by each bit (0.67 at 8, 0.166 at 10, 0.0026 at 16)")
      ->check(CLI::Range(4, 16))
      ->capture_default_str();
  enc->add_option("--scalar-bits", a.attributes.scalar_bits,
                  "Bits over each scalar's range (1..24): error at most half of range/(2^bits-1)")
      ->check(CLI::Range(1, 24))
      ->capture_default_str();
  enc->add_option("--texcoord-bits", a.attributes.texcoord_bits,
                  "Bits over the range of u and of v (1..24): error at most half a step")
      ->check(CLI::Range(1, 24))
      ->capture_default_str();
  enc->add_flag("--exact-attributes", a.attributes.exact,
                "Store normals, scalars and texture coordinates bit for bit (NaN, infinities, "
                "denormals, -0 included); colour is always exact. Without it a NaN or "
                "infinite value is an error (a zero-length normal comes back as (0, 0, 0))");
  enc->add_option("--max-memory", a.max_memory,
                  "Refuse (exit 7, no output file) a mesh whose loading and encoding would need "
                  "more than SIZE of memory, checked from the file's header before reading it: "
                  "bytes or a number with K, M, G, T (powers of 1024), e.g. 512M, 2G, 1.5GiB; "
                  "'none' = no check. Default 'auto': the memory available (the smallest of "
                  "MemAvailable, the cgroup's limit and ulimit -v/-d; no check if unknown)")
      ->type_name("SIZE")
      ->capture_default_str();
  return enc;
}

CLI::App *add_decode_command(CLI::App &app, DecodeArgs &a) {
  CLI::App *dec = app.add_subcommand("decode", "Decompress a .pomar file into a mesh file");
  dec->add_option("input", a.in, "Input .pomar file")->required();
  dec->add_option("output", a.out,
                  "Output mesh; the format follows the extension (.ply .obj .off .stl). PLY keeps "
                  "every attribute; OBJ colour, normals, UVs and texture names (OUT.mtl beside "
                  "it); OFF colour and normals; STL none (a warning names what is not written)")
      ->required();
  dec->add_option("-l,--level", a.level,
                  "Stop after L refinement levels (0 = base mesh; default: full resolution). With "
                  "--cluster/--sphere/--box: the level of every other cluster (default: the base "
                  "clustered mesh)")
      ->check(CLI::NonNegativeNumber);
  dec->add_option("--cluster", a.clusters,
                  "Refine cluster ID to LEVEL (default: finest); repeatable. Neighbouring "
                  "clusters are refined as needed (at most one level apart)")
      ->type_name("ID[:LEVEL]");
  dec->add_option("--sphere", a.spheres,
                  "Refine the clusters with a vertex within R of (X,Y,Z) (of the base clustered "
                  "mesh) to LEVEL; repeatable")
      ->type_name("X,Y,Z,R[:LEVEL]");
  dec->add_option("--box", a.boxes,
                  "Refine the clusters with a vertex in the box to LEVEL; repeatable")
      ->type_name("X0,Y0,Z0,X1,Y1,Z1[:LEVEL]");
  dec->add_flag("--stats", a.stats,
                "Print clusters decoded, bytes read of the file size, vertices and time");
  dec->add_flag("--ascii", a.ascii, "Write ASCII PLY instead of binary");
  dec->add_flag("--skip-damaged", a.skip_damaged,
                "Decode around damaged or missing blocks (bit rot, truncated download) instead "
                "of failing: a damaged cluster stays at the base clustered level and its "
                "neighbours at most one level finer per step, a damaged global level stops the "
                "decoding before it. Skipped blocks are listed on stderr and the exit status is "
                "4 (the output is written). The header, base mesh, tables and index must be "
                "intact");
  dec->add_flag("-q,--quiet", a.quiet, "Print nothing on success");
  dec->add_option("--threads", a.threads,
                  "Threads for the clusters of a random-access file (0 = every core this process "
                  "may use, at most 8; pure progressive files decode on one); the output is the "
                  "same for any number")
      ->capture_default_str();
  dec->add_flag("--no-attributes", a.no_attributes,
                "Write positions and triangles only: leave out colour, normals, scalars and "
                "texture coordinates (their codes, interleaved with the positions, are read "
                "past without being decoded into values: less memory, a little less time)");
  dec->add_option("--max-memory", a.max_memory,
                  "Refuse (exit 7, no output file) a file whose decoding would need more than "
                  "SIZE of memory, checked from its header (with --cluster/--sphere/--box: the "
                  "base clustered mesh, then the clusters asked for, estimated from the level "
                  "table): as for encode, e.g. 512M, 2G, 'none'; default 'auto' = the memory "
                  "available. A full decode to a binary .ply that would not fit is written "
                  "region by region within SIZE instead (the same file, byte for byte; slower: "
                  "each region is decoded twice, with the clusters its level map needs around "
                  "it; random-access files without attributes or a lossless record); exit 7 "
                  "then names the least SIZE that works")
      ->type_name("SIZE")
      ->capture_default_str();
  return dec;
}

CLI::App *add_info_command(CLI::App &app, InfoArgs &a) {
  CLI::App *inf =
      app.add_subcommand("info", "Describe a .pomar file: counts, levels, bits per vertex");
  inf->add_option("input", a.in, "Input .pomar file")->required();
  inf->add_flag("--json", a.json,
                "One JSON object (keys: vertices, faces, bits, levels, "
                "connectivity_bits, geometry_bits, total_bytes, ...)");
  inf->add_flag("--check", a.check,
                "Check every block's checksum instead (no decoding); exit status 4 lists the "
                "damaged or missing blocks");
  inf->add_option("--max-memory", a.max_memory,
                  "With --check: refuse (exit 7) a textured file whose base mesh, decoded to "
                  "check its texture coordinates, would need more than SIZE (as for decode, e.g. "
                  "512M, 'none'; default 'auto' = the memory available)")
      ->type_name("SIZE")
      ->capture_default_str();
  return inf;
}

CLI::App *add_verify_command(CLI::App &app, VerifyArgs &a) {
  CLI::App *ver = app.add_subcommand(
      "verify", "Check that a .pomar file (or a mesh decoded from it) is the original, losslessly");
  ver->add_option("original", a.original, "The mesh that was encoded")->required();
  ver->add_option("pomar", a.file, "The .pomar file")->required();
  ver->add_option("decoded", a.decoded, "A mesh decoded from it (default: decode in memory)");
  ver->add_flag("--repair", a.repair,
                "The file was encoded with encode --repair: compare with the original as repaired "
                "(the same cut as encode --repair; lossless means equal to that mesh)");
  ver->add_option("--drop", a.drop,
                  "The file was encoded with encode --drop LIST: do not expect those attributes")
      ->type_name("LIST");
  return ver;
}

} // namespace
} // namespace pomar::tool

int main(int argc, char **argv) {
  CLI::App app{
      "pomar: progressive, randomly accessible compression of manifold triangle meshes "
      "(POMAR, Maglo et al. 2013).\n\nExamples:\n"
      "  pomar encode bunny.ply bunny.pomar          # 12-bit grid, all levels\n"
      "  pomar info bunny.pomar                      # levels and bits per vertex\n"
      "  pomar decode bunny.pomar coarse.ply --level 10\n"
      "  pomar decode bunny.pomar ear.ply --sphere -0.06,0.16,0.0,0.02 --stats\n"
      "  pomar verify bunny.ply bunny.pomar          # lossless check\n"
      "  pomar encode messy.stl messy.pomar          # any mesh: the cut is stored, exact decode\n"
      "  pomar encode messy.stl fixed.pomar --repair # keep the cut (manifold) mesh instead\n"
      "  pomar verify messy.stl fixed.pomar --repair # lossless w.r.t. the repaired mesh\n"};
  app.require_subcommand(1);
  app.footer("Exit status: 0 success, 1 other error, 2 unusable value (level, cluster, size), "
             "3 verify mismatch, 4 damaged or truncated .pomar (or damaged blocks found or "
             "skipped), 5 mesh the codec cannot take, 6 I/O, 7 memory limit, 8 unsupported "
             ".pomar version or section, 70 internal error.");
  // Ctrl-C or kill during a write: no temporary file left, the old output untouched.
  pomar::remove_temporary_files_on_signals();
  // A write past the file size limit (ulimit -f) fails with EFBIG, an I/O error (exit 6,
  // the temporary file removed), instead of killing the tool.
  std::signal(SIGXFSZ, SIG_IGN);
  app.set_version_flag("--version",
                       "pomar 0.1.0 (writes .pomar format versions 1, 3 and 4, reads 1 to 4)");

  using namespace pomar::tool;
  EncodeArgs encode_args;
  DecodeArgs decode_args;
  InfoArgs info_args;
  VerifyArgs verify_args;
  const CLI::App *enc = add_encode_command(app, encode_args);
  const CLI::App *dec = add_decode_command(app, decode_args);
  const CLI::App *inf = add_info_command(app, info_args);
  const CLI::App *ver = add_verify_command(app, verify_args);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &e) {
    return app.exit(e);
  }
  try {
    if (*enc)
      return run_encode(encode_args);
    if (*dec)
      return run_decode(decode_args);
    if (*inf)
      return run_info(info_args);
    if (*ver)
      return run_verify(verify_args);
  } catch (const pomar::Error &e) {
    std::fprintf(stderr, "pomar: error: %s\n", pomar::printable(e.what()).c_str());
    return exit_status(e);
  } catch (const std::bad_alloc &) {
    // (Every size the codec allocates from is checked first: this is the machine's limit.)
    std::fprintf(stderr, "pomar: error: out of memory (use --max-memory to be refused "
                         "before the work starts)\n");
    return kExitMemory;
  } catch (const std::exception &e) {
    // Every throw of the codec and the tool has a kind: anything else is a bug.
    std::fprintf(stderr, "pomar: error: internal error: %s (please report it)\n",
                 pomar::printable(e.what()).c_str());
    return kExitInternal;
  }
  return 0;
}
