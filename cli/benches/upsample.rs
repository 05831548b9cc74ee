//! GPU cost of the bilateral upsample pass against a hardware-filtered bilinear pass over the
//! same low-res color (the edge scene at r = 2). GPU timestamps around a run of recordings where
//! the device has them, else the wall time of the run's submission and wait (each line names
//! its clock); on a software GPU read the ratio, not the absolute figures. `lodkit demo` measures the
//! same ratio, and whole-frame speed-ups per resize factor, for its report.
//!
//! Then the same for a pass that only makes eq. 1's nine texel loads: the floor of any per-pixel
//! eq. 1 on this GPU; and the packed L's upsample (4 + 1 loads), its loads alone, and the fold-in
//! upsample inside a composite pass against the same composite with a bilinear sample.
//!
//! `cargo bench -p lodkit-cli --bench upsample [-- WIDTH HEIGHT PAIRS]` (default 1280 x 720, 60 pairs)

use lodkit_cli::demo::fixtures::clock::RECORDINGS;
use lodkit_cli::demo::fixtures::clock::Timer;
use lodkit_cli::demo::measures::packed_upsample_timing::packed_upsample_vs_bilinear;
use lodkit_cli::demo::measures::upsample_timing::upsample_vs_bilinear;
use lodkit_cli::demo::open_gpu;

fn main() {
    let args: Vec<u32> = std::env::args().filter_map(|a| a.parse().ok()).collect();
    let size = (
        args.first().copied().unwrap_or(1280),
        args.get(1).copied().unwrap_or(720),
    );
    let pairs = args.get(2).copied().unwrap_or(60) as usize;
    let gpu = match open_gpu() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("upsample bench skipped: {e}");
            return;
        }
    };
    println!("adapter: {}", gpu.adapter_summary());
    let ratios = Timer::new(&gpu, RECORDINGS).and_then(|timer| {
        let r = upsample_vs_bilinear(&gpu, &timer, size, 2.0, pairs)?;
        let packed = packed_upsample_vs_bilinear(&gpu, &timer, size, 2.0, pairs)?;
        Ok(r.into_iter().chain(packed).collect::<Vec<_>>())
    });
    match ratios {
        Ok(ratios) => {
            for r in ratios {
                println!(
                    "{}x{}, {pairs} interleaved pairs ({}): {} {:.3} ms, {} {:.3} ms, median ratio {:.3}",
                    size.0,
                    size.1,
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
