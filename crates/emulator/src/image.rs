//! The image: `target/firmware/<motor>.elf` as `motorgen firmware` writes it, built
//! once per motor for the default board (and reused by every test of that motor).
//!
//! ELF reading uses the `object` crate (already in the lock for `motorgen firmware`):
//! loadable segments by physical address (LMA: `.data`'s initial values live in flash),
//! symbols by name.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

use object::read::elf::{ElfFile32, ProgramHeader};
use object::{Object, ObjectSymbol};

/// A loaded image.
#[derive(Clone, Debug)]
pub struct Image {
    /// (load address, bytes) of each PT_LOAD segment.
    pub segments: Vec<(u32, Vec<u8>)>,
    /// The vector table at 0x0800_0000 (initial SP, reset, exceptions, 102 interrupts).
    pub vectors: Vec<u32>,
    /// (name, address, size) of every symbol.
    pub symbols: Vec<(String, u32, u32)>,
}

impl Image {
    /// Parses an ELF file.
    pub fn parse(bytes: &[u8]) -> Result<Self, String> {
        let elf = ElfFile32::<object::Endianness>::parse(bytes).map_err(|e| e.to_string())?;
        let endian = elf.endian();
        let mut segments = Vec::new();
        for ph in elf.elf_program_headers() {
            if ph.p_type(endian) != object::elf::PT_LOAD || ph.p_filesz(endian) == 0 {
                continue;
            }
            let data = ph
                .data(endian, bytes)
                .map_err(|()| "segment outside the file".to_string())?;
            segments.push((ph.p_paddr(endian), data.to_vec()));
        }
        let flash = segments
            .iter()
            .find(|(a, _)| *a == 0x0800_0000)
            .ok_or("no segment at 0x0800_0000 (the vector table)")?;
        let vectors = flash
            .1
            .chunks_exact(4)
            .take(16 + 102)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let symbols = elf
            .symbols()
            .filter_map(|s| Some((s.name().ok()?.to_string(), s.address() as u32, s.size() as u32)))
            .collect();
        Ok(Self {
            segments,
            vectors,
            symbols,
        })
    }

    /// The address of the first symbol whose (mangled) name contains `part`.
    pub fn symbol(&self, part: &str) -> Option<u32> {
        self.symbols.iter().find(|(n, _, _)| n.contains(part)).map(|s| s.1)
    }
}

/// The repository root (`motor_test_support::repo`).
pub fn repo() -> PathBuf {
    motor_test_support::repo()
}

/// Every motor stem in `motors/`, sorted; `EMULATOR_MOTORS=a,b` restricts the scenarios
/// to those motors (CI sets nothing: every motor). An empty `motors/` or a name in
/// `EMULATOR_MOTORS` that is not a motor fails (`motor_test_support`), never an empty
/// list every scenario loops over zero times.
pub fn motors() -> Vec<String> {
    motor_test_support::motor_stems_filtered("EMULATOR_MOTORS")
}

/// One build at a time: the firmware workspace's target directory holds one image.
static BUILD: Mutex<()> = Mutex::new(());

/// Images built by this process, by motor.
static IMAGES: Mutex<Vec<(String, Image)>> = Mutex::new(Vec::new());

/// The image of `motor`, built on first use in this process (see [`build`]).
pub fn image(motor: &str) -> Result<Image, String> {
    let mut cache = IMAGES.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some((_, i)) = cache.iter().find(|(m, _)| m == motor) {
        return Ok(i.clone());
    }
    let i = build(motor)?;
    cache.push((motor.to_string(), i.clone()));
    Ok(i)
}

/// FNV-1a (64 bit) of every input of the image: the firmware sources and build scripts,
/// the lock files, the motor's spec, the board files, codegen's sources and templates
/// (the build script runs the design engine), the toolchain file.
fn inputs_hash(motor: &str) -> u64 {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(rd) = std::fs::read_dir(dir) else { return };
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                if p.file_name()
                    .is_some_and(|n| n != "target" && n != "tests" && n != "benches")
                {
                    walk(&p, out);
                }
            } else {
                out.push(p);
            }
        }
    }
    let repo = repo();
    let mut files = Vec::new();
    for d in [
        "firmware/app",
        "firmware/config",
        "firmware/control",
        "crates/codegen/src",
        "templates",
        "boards",
    ] {
        walk(&repo.join(d), &mut files);
    }
    for f in [
        "Cargo.lock",
        "firmware/Cargo.lock",
        "firmware/Cargo.toml",
        "rust-toolchain.toml",
    ] {
        files.push(repo.join(f));
    }
    files.push(repo.join("motors").join(format!("{motor}.toml")));
    files.sort();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for f in files {
        let name = f.strip_prefix(&repo).unwrap_or(&f).to_string_lossy().into_owned();
        for b in name.bytes().chain(std::fs::read(&f).unwrap_or_default()) {
            h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// The board `motor`'s image is built for: the default board when `motorgen check`
/// accepts the motor on it, else the first other board in `boards/` that it fits (a
/// motor whose peak current or DC link the default board cannot measure — the traction
/// motors on `motorgen-reference-400a`); an error naming every refusal if none fits.
pub fn board_for(motor: &str) -> Result<String, String> {
    let read = |file: String| -> Result<(String, String), String> {
        let text = std::fs::read_to_string(repo().join(&file)).map_err(|e| format!("{file}: {e}"))?;
        Ok((file, text))
    };
    let (spec_file, spec) = read(format!("motors/{motor}.toml"))?;
    let mut boards = motor_test_support::board_stems();
    boards.sort_by_key(|b| b != codegen::board::DEFAULT_BOARD);
    let mut refusals = Vec::new();
    for b in boards {
        let (board_file, board_text) = read(format!("boards/{b}.toml"))?;
        match codegen::design_with_board(&spec_file, &spec, &board_file, &board_text) {
            Ok(_) => return Ok(b),
            Err(e) => refusals.push(e.to_string()),
        }
    }
    Err(format!("{motor} fits no board in boards/:\n{}", refusals.join("\n")))
}

/// `target/firmware/<motor>.elf` for the motor's board ([`board_for`]: the
/// default board, or `target/firmware/<board>/<motor>.elf` for a motor that only fits
/// another), built as `motorgen firmware` builds it (`MOTOR=<motor> BOARD=<board> cargo
/// build --release --target thumbv7em-none-eabihf -p motor-firmware` in `firmware/`, its
/// own target directory) and copied there with a stamp of its inputs: an image whose
/// stamp matches is reused without running cargo (switching `MOTOR` makes cargo rebuild
/// the image, a minute each on 2 cores).
pub fn build(motor: &str) -> Result<Image, String> {
    let _guard = BUILD.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let repo = repo();
    let board = board_for(motor)?;
    let mut dir = repo.join("target").join("firmware");
    if board != codegen::board::DEFAULT_BOARD {
        dir = dir.join(&board);
    }
    let elf = dir.join(format!("{motor}.elf"));
    let stamp = dir.join(format!("{motor}.emulator-stamp"));
    let hash = format!("{:016x}", inputs_hash(motor));
    if std::fs::read_to_string(&stamp).is_ok_and(|s| s == hash)
        && let Ok(bytes) = std::fs::read(&elf)
    {
        return Image::parse(&bytes);
    }
    let firmware = repo.join("firmware");
    let out = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args([
            "build",
            "--locked",
            "--release",
            "--target",
            "thumbv7em-none-eabihf",
            "-p",
            "motor-firmware",
        ])
        .current_dir(&firmware)
        .env("CARGO_TARGET_DIR", firmware.join("target"))
        .env("MOTOR", motor)
        .env("BOARD", &board)
        .env_remove("MOTORS_DIR")
        .env_remove("BOARDS_DIR")
        .output()
        .map_err(|e| format!("cargo: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "building the {motor} image failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let built = firmware.join("target/thumbv7em-none-eabihf/release/motor-firmware");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    std::fs::copy(&built, &elf).map_err(|e| format!("{}: {e}", built.display()))?;
    std::fs::write(&stamp, &hash).map_err(|e| e.to_string())?;
    let bytes = std::fs::read(&elf).map_err(|e| format!("{}: {e}", elf.display()))?;
    Image::parse(&bytes)
}
