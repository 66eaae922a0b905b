//! The image: `target/firmware/[<board>/]<motor>.elf` as `motorgen firmware` writes it,
//! built once per motor and board file (and reused by every test of that pair, across
//! runs through a stamp of its inputs).
//!
//! ELF reading uses the `object` crate (already in the lock for `motorgen firmware`):
//! loadable segments by physical address (LMA: `.data`'s initial values live in flash),
//! symbols by name.

use std::path::{Path, PathBuf};
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

/// The board file an image is built for: one of `boards/`, or a variant of one (the
/// tests' boards with one fact changed), written where the build script reads it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoardFile {
    /// Its stem (`BOARD`).
    pub stem: String,
    /// Its text.
    pub text: String,
    /// A variant: not the file in `boards/`.
    pub variant: bool,
}

impl BoardFile {
    /// `boards/<stem>.toml`.
    pub fn shipped(stem: &str) -> Result<Self, String> {
        let file = format!("boards/{stem}.toml");
        let text = std::fs::read_to_string(repo().join(&file)).map_err(|e| format!("{file}: {e}"))?;
        Ok(Self {
            stem: stem.to_string(),
            text,
            variant: false,
        })
    }

    /// A board file with the text `text`, named `<stem>.toml` (a variant of a shipped one).
    pub fn variant(stem: &str, text: String) -> Self {
        Self {
            stem: stem.to_string(),
            text,
            variant: true,
        }
    }

    /// The name messages give it: `boards/<stem>.toml`, or `variant-<hash>/<stem>.toml`.
    pub fn file_name(&self) -> String {
        if self.variant {
            format!("variant-{:016x}/{}.toml", fnv(self.text.as_bytes()), self.stem)
        } else {
            format!("boards/{}.toml", self.stem)
        }
    }
}

/// FNV-1a, 64 bit.
fn fnv(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// One build at a time: the firmware workspace's target directory holds one image.
static BUILD: Mutex<()> = Mutex::new(());

/// Images built by this process, by motor and board text.
static IMAGES: Mutex<Vec<(String, String, Image)>> = Mutex::new(Vec::new());

/// The image of `motor` on `board`, built on first use in this process (see [`build`]).
pub fn image(motor: &str, board: &BoardFile) -> Result<Image, String> {
    let mut cache = IMAGES.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some((_, _, i)) = cache.iter().find(|(m, b, _)| m == motor && *b == board.text) {
        return Ok(i.clone());
    }
    let i = build(motor, board)?;
    cache.push((motor.to_string(), board.text.clone(), i.clone()));
    Ok(i)
}

/// FNV-1a (64 bit) of every input of the image: the firmware sources and build scripts,
/// the lock files, the motor's spec, the board file's text, codegen's sources and
/// templates (the build script runs the design engine), the toolchain file.
fn inputs_hash(motor: &str, board: &BoardFile) -> u64 {
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
    let mut bytes = Vec::new();
    for f in files {
        let name = f.strip_prefix(&repo).unwrap_or(&f).to_string_lossy().into_owned();
        bytes.extend(name.bytes());
        bytes.extend(std::fs::read(&f).unwrap_or_default());
    }
    bytes.extend(board.stem.bytes());
    bytes.extend(board.text.bytes());
    fnv(&bytes)
}

/// The image of `motor` on `board`, built as `motorgen firmware` builds it
/// (`MOTOR=<motor> BOARD=<stem> cargo build --release --target thumbv7em-none-eabihf -p
/// motor-firmware` in `firmware/`, its own target directory; a variant's text is written
/// to its own `BOARDS_DIR`) and copied to `target/firmware/[<board>/]<motor>.elf` (where
/// `motorgen firmware` puts it; variants under `target/firmware/variant-<hash>/`) with a
/// stamp of its inputs: an image whose stamp matches is reused without running cargo.
pub fn build(motor: &str, board: &BoardFile) -> Result<Image, String> {
    let _guard = BUILD.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let repo = repo();
    let mut dir = repo.join("target").join("firmware");
    if board.variant {
        dir = dir.join(format!("variant-{:016x}", fnv(board.text.as_bytes())));
    } else if board.stem != codegen::board::DEFAULT_BOARD {
        dir = dir.join(&board.stem);
    }
    let elf = dir.join(format!("{motor}.elf"));
    let stamp = dir.join(format!("{motor}.emulator-stamp"));
    let hash = format!("{:016x}", inputs_hash(motor, board));
    if std::fs::read_to_string(&stamp).is_ok_and(|s| s == hash)
        && let Ok(bytes) = std::fs::read(&elf)
    {
        return Image::parse(&bytes);
    }
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let boards_dir = if board.variant {
        let d = dir.join("boards");
        std::fs::create_dir_all(&d).map_err(|e| format!("{}: {e}", d.display()))?;
        let f = d.join(format!("{}.toml", board.stem));
        std::fs::write(&f, &board.text).map_err(|e| format!("{}: {e}", f.display()))?;
        d
    } else {
        repo.join("boards")
    };
    let out = motor_test_support::firmware_image_build(motor, &board.stem, &boards_dir)
        .output()
        .map_err(|e| format!("cargo: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "building the {motor} image on {} failed:\n{}",
            board.file_name(),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let built = motor_test_support::firmware_image_path();
    std::fs::copy(&built, &elf).map_err(|e| format!("{}: {e}", built.display()))?;
    std::fs::write(&stamp, &hash).map_err(|e| e.to_string())?;
    let bytes = std::fs::read(&elf).map_err(|e| format!("{}: {e}", elf.display()))?;
    Image::parse(&bytes)
}
