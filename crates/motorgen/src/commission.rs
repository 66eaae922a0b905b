//! `motorgen commission SPEC --board B --can IFACE --out DIR <routine> …`: starts a
//! chapter-6 routine on the drive over CAN, receives its capture, writes the CSV
//! recording into DIR and identifies from it as `motorgen identify … --candump` does.
//!
//! The session is `motor_commission::commission`'s ([`commission::plan`] checks the
//! options before the bus is touched, [`commission::Plan::run`] runs the session and
//! checks the captures as a log's); here the files are read, the SocketCAN interface is
//! opened ([`motor_commission::socket::open`]), the CSV files are written, and the
//! identification is [`crate::identify::identify`]'s, as for `identify --candump`.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use motor_commission::commission::{self, FrameBus, Options, Plan, RoutineOptions};
use motor_commission::frequency_response as fr;
use motor_commission::sim_drive::SimulatedDrive;

use crate::atomic;
use crate::exit::{Exit, Failure};
use crate::identify::AxisArg;
use crate::output::{out, outln};

/// `motorgen commission`'s options.
#[derive(Args)]
pub struct CommissionArgs {
    /// The motor spec (its scalings encode the command and decode the capture; the
    /// identified values are written into it).
    #[arg(value_name = "SPEC")]
    pub spec: PathBuf,
    /// The board file whose CAN identifiers the drive uses.
    #[arg(long, value_name = "BOARD_FILE")]
    pub board: PathBuf,
    /// The SocketCAN interface the drive is on, up at the board's bit rate (Linux).
    #[arg(long, value_name = "IFACE", required_unless_present = "sim", conflicts_with = "sim")]
    pub can: Option<String>,
    /// Run the session against the simulated drive instead of a bus: the firmware's
    /// commissioning mode and control step on `verify`'s motor simulation, rotor held.
    #[arg(long, global = true)]
    pub sim: bool,
    /// With `--sim`: a factor on the simulated plant, KEY=FACTOR with KEY one of R, Ld,
    /// Lq, delay (repeatable), e.g. `--sim-scale Lq=0.7`.
    #[arg(long, value_name = "KEY=FACTOR", global = true)]
    pub sim_scale: Vec<String>,
    /// Directory for the CSV recording of the capture (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    // These four are `global`: accepted before the routine or after its own options
    // (`… step --axis d --voltage "4 V" --trip "30 A" --dry-run`, as README shows).
    /// How long to wait for the whole capture, e.g. "30 s".
    #[arg(long, default_value = "30 s", value_name = "TIME", global = true)]
    pub timeout: String,
    /// Control periods per captured sample (default: the smallest whose capture fits
    /// the drive's buffer).
    #[arg(long, value_name = "N", global = true)]
    pub decimation: Option<u16>,
    /// Print the change to the spec instead of writing it (the CSV is still written).
    #[arg(long, global = true)]
    pub dry_run: bool,
    /// Identification date written to `date` (YYYY-MM-DD; default: today, UTC).
    #[arg(long, global = true)]
    pub date: Option<String>,
    /// The routine.
    #[command(subcommand)]
    pub routine: RoutineArg,
}

/// The routines of thesis A chapter 6.
#[derive(Subcommand, Clone)]
pub enum RoutineArg {
    /// Blocked-rotor voltage step on one axis (§6.2): R and L of that axis.
    Step {
        /// The axis.
        #[arg(long, value_enum)]
        axis: AxisArg,
        /// Step voltage, e.g. "4 V".
        #[arg(long)]
        voltage: String,
        /// Current trip level, e.g. "10 A".
        #[arg(long)]
        trip: String,
    },
    /// ψ_M at zero current with the rotor driven at speed (§6.5).
    Flux,
    /// Resolver offset by α-axis alignment of a free rotor (§6.3).
    ResolverOffset {
        /// Alignment voltage on α, e.g. "3 V".
        #[arg(long)]
        voltage: String,
    },
    /// Pole-pair ratio and direction by a turning voltage vector (§6.4).
    PolePairRatio {
        /// Voltage of the turning vector, e.g. "3 V".
        #[arg(long)]
        voltage: String,
    },
    /// The current loop's frequency response on one axis at standstill (rotor held for
    /// q): margins and crossover against the design, the plant fitted to it, the retune;
    /// writes DIR/frequency-response-d.json (or -q.json) and the capture's CSV.
    FrequencyResponse {
        /// The axis.
        #[arg(long, value_enum)]
        axis: AxisArg,
        /// Peak of the injected multisine, e.g. "5 V" (default: 5 % of U_dc/√3).
        #[arg(long)]
        amplitude: Option<String>,
        /// The lines, FIRST/PER_OCTAVE: the first harmonic of the capture period and the
        /// lines per octave up to the Nyquist frequency, e.g. "4/3" (default: two octaves
        /// below the designed crossover, as many per octave as 32 lines allow).
        #[arg(long)]
        frequencies: Option<String>,
        /// Write the fitted L (and R, where the lines determine it) into the spec's
        /// `[motor.identified]`.
        #[arg(long)]
        write: bool,
    },
}

/// The interface's name in messages and logs: `--can`'s, or `sim` for `--sim`.
fn iface(a: &CommissionArgs) -> String {
    a.can.clone().unwrap_or_else(|| "sim".into())
}

/// The library's options of `a`.
fn options(a: &CommissionArgs) -> Options {
    Options {
        iface: iface(a),
        timeout: a.timeout.clone(),
        decimation: a.decimation,
        date: a.date.clone(),
        routine: match &a.routine {
            RoutineArg::Step { axis, voltage, trip } => RoutineOptions::Step {
                axis: (*axis).into(),
                voltage: voltage.clone(),
                trip: trip.clone(),
            },
            RoutineArg::Flux => RoutineOptions::Flux,
            RoutineArg::ResolverOffset { voltage } => RoutineOptions::ResolverOffset {
                voltage: voltage.clone(),
            },
            RoutineArg::PolePairRatio { voltage } => RoutineOptions::PolePairRatio {
                voltage: voltage.clone(),
            },
            // Planned by `frequency_response::plan` (`run` takes that path first).
            RoutineArg::FrequencyResponse { axis, .. } => RoutineOptions::Step {
                axis: (*axis).into(),
                voltage: String::new(),
                trip: String::new(),
            },
        },
    }
}

/// `motorgen commission`.
pub fn run(a: &CommissionArgs) -> Result<(), Failure> {
    if a.can.is_some() && !a.sim_scale.is_empty() {
        return Err(motor_commission::Error::Option(motor_commission::Problem::new(
            "--sim-scale",
            "perturbs the simulated plant, and the session runs on a bus (--can)",
            "--sim-scale with --sim",
        ))
        .into());
    }
    if let RoutineArg::FrequencyResponse {
        axis,
        amplitude,
        frequencies,
        write,
    } = &a.routine
    {
        let o = fr::Options {
            iface: iface(a),
            timeout: a.timeout.clone(),
            axis: (*axis).into(),
            amplitude: amplitude.clone(),
            frequencies: frequencies.clone(),
        };
        return frequency_response(a, &o, *write);
    }
    // Everything that does not need the bus is checked first.
    let plan = plan(a)?;
    match &a.can {
        Some(can) => {
            let mut bus = motor_commission::socket::open(can, plan.bit_rate)?;
            run_planned(&mut bus, a, &plan)
        }
        None => {
            let (design, spec) = sim_design(a)?;
            let mut drive = sim_drive(a, &design, &spec)?;
            run_planned(&mut drive, a, &plan)
        }
    }
}

/// The design of `a`'s spec on its board and the parsed spec (for the simulated drive).
fn sim_design(a: &CommissionArgs) -> Result<(codegen::Design, codegen::spec::Spec), Failure> {
    let spec = crate::read_input(&a.spec);
    let board = crate::read_board_input(&a.board);
    let (spec_text, board_text) = (spec.text()?, board.text()?);
    let design = codegen::design_with_board(&spec.name, spec_text, &board.name, board_text)
        .map_err(motor_commission::Error::from)?;
    let parsed = codegen::spec::parse(codegen::Source {
        file: &spec.name,
        text: spec_text,
    })
    .map_err(motor_commission::Error::from)?;
    Ok((design, parsed))
}

/// The simulated drive of `design` (`--sim`): the firmware's commissioning mode on
/// `verify`'s bench at standstill, the plant perturbed by `--sim-scale`.
fn sim_drive(
    a: &CommissionArgs,
    design: &codegen::Design,
    spec: &codegen::spec::Spec,
) -> Result<SimulatedDrive, Failure> {
    let req = design.current_loop_request(motor_control::commissioning::Axis::D);
    let delay = req.loop_delay_s / req.sample_period_s;
    let scale = fr::SimScale::parse(&a.sim_scale, delay)?;
    let setup = motor_verify::Setup::new(spec, design);
    let mut bench = setup.bench(0.0);
    scale.apply(&mut bench.plant, delay);
    SimulatedDrive::new(design, bench, 0.0).ok_or_else(|| {
        Failure::from(motor_commission::Error::Option(motor_commission::Problem::new(
            "--board",
            "the design has no CAN interface",
            "a board file with a [can] section",
        )))
    })
}

/// `commission … frequency-response`: the session (on the bus or the simulated drive),
/// the JSON and CSV into `--out`, the summary, and with `--write` the fitted values into
/// the spec.
fn frequency_response(a: &CommissionArgs, o: &fr::Options, write: bool) -> Result<(), Failure> {
    atomic::check_out_dir(&a.out).map_err(|e| Failure::new(Exit::BadInput, e))?;
    let spec = crate::read_input(&a.spec);
    let board = crate::read_board_input(&a.board);
    let plan = fr::plan(o, &spec, &board)?;
    let m = match &a.can {
        Some(can) => {
            let mut bus = motor_commission::socket::open(can, plan.bit_rate)?;
            plan.run(&mut bus)?
        }
        None => {
            let (design, parsed) = sim_design(a)?;
            let mut drive = sim_drive(a, &design, &parsed)?;
            plan.run(&mut drive)?
        }
    };
    let axis = match o.axis {
        motor_control::commissioning::Axis::D => "d",
        motor_control::commissioning::Axis::Q => "q",
    };
    let files = vec![
        (
            a.out.join(format!("frequency-response-{axis}.json")),
            m.to_json().into_bytes(),
        ),
        (a.out.join(&m.csv.0), m.csv.1.clone().into_bytes()),
    ];
    let written = atomic::write_set(&a.out, &files)?;
    for ((path, _), w) in files.iter().zip(written) {
        outln!("{} {}", if w { "wrote" } else { "unchanged" }, path.display());
    }
    out!("{}", m.summary());
    if write {
        write_fitted(&a.spec, &m, &o.iface)?;
    }
    Ok(())
}

/// The fitted values into the spec's `[motor.identified]` (under the spec lock).
fn write_fitted(spec: &std::path::Path, m: &fr::Measurement, iface: &str) -> Result<(), Failure> {
    let mut lock = crate::atomic::LockedSpec::open(spec)?;
    let name = spec.display().to_string();
    let text = motor_commission::Input::from_bytes(name.clone(), std::mem::take(&mut lock.bytes))
        .text?
        .to_string();
    let date = crate::identify::today();
    let label = format!("frequency response {iface}");
    let files = vec![m.csv.0.clone()];
    let entries = m.entries();
    let source = codegen::Source {
        file: &name,
        text: &text,
    };
    let origin = motor_commission::writeback::Origin {
        date: &date,
        label: &label,
        files: &files,
    };
    // The updated spec must still design (as identify's write-back checks).
    let new = motor_commission::identify::update(&source, &entries, &origin)?.text;
    lock.replace(new.as_bytes())?;
    let keys: Vec<&str> = entries.iter().map(|e| e.key).collect();
    outln!("wrote [motor.identified] {} to {name}", keys.join(", "));
    Ok(())
}

/// `--out` a directory, then the library's checks of the options, spec and board.
fn plan(a: &CommissionArgs) -> Result<Plan, Failure> {
    atomic::check_out_dir(&a.out).map_err(|e| Failure::new(Exit::BadInput, e))?;
    let spec = crate::read_input(&a.spec);
    let board = crate::read_board_input(&a.board);
    Ok(commission::plan(&options(a), &spec, &board)?)
}

/// The session of `plan` on `bus`; the captures' CSV files written into `--out`, then
/// the identification from them.
fn run_planned<B: FrameBus>(bus: &mut B, a: &CommissionArgs, plan: &Plan) -> Result<(), Failure> {
    let captured = plan.run(bus)?;
    let files: Vec<(PathBuf, Vec<u8>)> = captured
        .files
        .iter()
        .map(|(name, csv)| (a.out.join(name), csv.clone().into_bytes()))
        .collect();
    let written = atomic::write_set(&a.out, &files)?;
    for ((path, _), w) in files.iter().zip(written) {
        outln!("{} {}", if w { "wrote" } else { "unchanged" }, path.display());
    }
    crate::identify::identify(&a.spec, a.dry_run, &captured.request)
}

#[cfg(test)]
mod tests {
    //! The command's files on the simulated drive (`motor_commission::sim_drive`: the
    //! firmware's commissioning mode and CAN encoder on the motor simulation of
    //! `verify`) in place of the socket: what is written where, with and without
    //! `--dry-run`. The session, its failures and the identification are tested on the
    //! library (`cargo test -p motor-commission --test it commission`), the exit codes
    //! in `tests/it/commission.rs`.

    use std::path::Path;

    use motor_commission::sim_drive::SimulatedDrive;

    use super::*;

    const BOARD: &str = "boards/motorgen-reference.toml";

    fn repo() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
    }

    /// The Fischer spec copied into a fresh directory and its design on the reference
    /// board.
    struct Bench {
        dir: tempfile::TempDir,
        spec: PathBuf,
        design: codegen::Design,
    }

    fn bench() -> Bench {
        let dir = tempfile::tempdir().unwrap();
        let spec = dir.path().join("fischer-ti085.toml");
        std::fs::copy(repo().join("motors/fischer-ti085.toml"), &spec).unwrap();
        let text = std::fs::read_to_string(&spec).unwrap();
        let board = std::fs::read_to_string(repo().join(BOARD)).unwrap();
        let design = codegen::design_with_board("fischer.toml", &text, BOARD, &board).unwrap();
        Bench { dir, spec, design }
    }

    impl Bench {
        /// The drive on the simulated motor at standstill.
        fn drive(&self) -> SimulatedDrive {
            let text = self.spec_text();
            let spec = codegen::spec::parse(codegen::Source {
                file: "fischer.toml",
                text: &text,
            })
            .unwrap();
            let setup = motor_verify::Setup::new(&spec, &self.design);
            SimulatedDrive::new(&self.design, setup.bench(0.0), 0.0).unwrap()
        }

        /// A d-axis step to 30 % of the current limit, tripping at 80 %.
        fn args(&self, dry_run: bool) -> CommissionArgs {
            let d = &self.design;
            let r = d.motor.phase_resistance_ohm;
            let i_max = d.motor.peak_current_a.min(d.scaling.phase_current.full_scale);
            CommissionArgs {
                spec: self.spec.clone(),
                board: repo().join(BOARD),
                can: Some("sim0".into()),
                sim: false,
                sim_scale: Vec::new(),
                out: self.dir.path().join("out"),
                timeout: "60 s".into(),
                decimation: None,
                dry_run,
                date: Some("2025-03-14".into()),
                routine: RoutineArg::Step {
                    axis: AxisArg::D,
                    voltage: format!("{} V", 0.3 * i_max * r),
                    trip: format!("{} A", 0.8 * i_max),
                },
            }
        }

        fn spec_text(&self) -> String {
            std::fs::read_to_string(&self.spec).unwrap()
        }

        fn outputs(&self) -> Vec<PathBuf> {
            match std::fs::read_dir(self.dir.path().join("out")) {
                Ok(d) => d.map(|e| e.unwrap().path()).collect(),
                Err(_) => Vec::new(),
            }
        }

        /// `motorgen commission` with the simulated drive as its bus.
        fn run(&self, a: &CommissionArgs) -> Result<(), Failure> {
            run_planned(&mut self.drive(), a, &plan(a)?)
        }
    }

    /// A d step: the capture's CSV in `--out` under its name, the identified values and
    /// the live log in the spec.
    #[test]
    fn run_writes_the_csv_and_the_spec() {
        let b = bench();
        let before = b.spec_text();
        b.run(&b.args(false)).unwrap();
        let out = b.outputs();
        assert_eq!(out.len(), 1, "{out:?}");
        let name = out[0].file_name().unwrap().to_string_lossy().into_owned();
        // Period 0 of the simulation is 1.7e9 s = 2023-11-14 22:13:20 UTC.
        assert!(name.starts_with("fischer-ti085-step-d-2023-11-14T2213"), "{name}");
        let csv = std::fs::read_to_string(&out[0]).unwrap();
        assert!(csv.starts_with("# motorgen recording: step\n"), "{csv}");
        let text = b.spec_text();
        assert_ne!(text, before);
        assert!(
            text.contains("d_inductance = ") && text.contains("sim0 (live)"),
            "{text}"
        );
    }

    /// `--dry-run`: the CSV is written, the spec is not.
    #[test]
    fn dry_run_leaves_the_spec() {
        let b = bench();
        let before = b.spec_text();
        b.run(&b.args(true)).unwrap();
        assert_eq!(b.spec_text(), before);
        assert_eq!(b.outputs().len(), 1);
    }
}
