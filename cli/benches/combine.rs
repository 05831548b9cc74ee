//! GPU cost of the frame-sequential combine pass against a plain fullscreen pass that reads the
//! same seven textures (color, id and depth of both buffers, the object motion) and writes one:
//! the pass's own overhead.
//! GPU timestamps around a run of recordings where the device has them, else the wall time of
//! the run's submission and wait (each line names its clock); on a software GPU read the ratio,
//! not the absolute figures. `lodkit demo` measures the same ratio for its report. Then its floors: the
//! 8 main-path loads alone, and those with the 4 loads of its id-mismatch branch all made. Last,
//! the combine of the same frames in buffers without object motion (`combine_at`) against a copy
//! of its six textures.
//!
//! `cargo bench -p lodkit-cli --bench combine [-- SIZE PAIRS]` (default 512 x 512, 200 pairs)

use lodkit_cli::demo::fixtures::clock::RECORDINGS;
use lodkit_cli::demo::fixtures::clock::Timer;
use lodkit_cli::demo::measures::combine_timing::combine_vs_copy;
use lodkit_cli::demo::open_gpu;

fn main() {
    let args: Vec<u32> = std::env::args().filter_map(|a| a.parse().ok()).collect();
    let size = args.first().copied().unwrap_or(512);
    let pairs = args.get(1).copied().unwrap_or(200) as usize;
    let gpu = match open_gpu() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("combine bench skipped: {e}");
            return;
        }
    };
    println!("adapter: {}", gpu.adapter_summary());
    let ratios = Timer::new(&gpu, RECORDINGS).and_then(|t| combine_vs_copy(&gpu, &t, size, pairs));
    match ratios {
        Ok(ratios) => {
            for r in ratios {
                println!(
                    "{size}x{size}, {pairs} interleaved pairs ({}): {} {:.3} ms, {} {:.3} ms, median ratio {:.3}",
                    r.clock.label(),
                    r.pass,
                    r.pass_ms,
                    r.baseline,
                    r.baseline_ms,
                    r.ratio
                );
            }
        }
        Err(e) => eprintln!("error: {e}"),
    }
}
