//! The mutator of the mutation fuzz (`scripts/mutation-fuzz.sh`): writes one mutant
//! of a recording or baked file, chosen by a seed, for the real binary to be run on.
//!
//! `cargo run --release -p trisort-testkit --example mutate -- KIND IN OUT SEED` with KIND
//! `recording` or `baked`. The seed picks one of three kinds of mutant, so each reaches a
//! different layer of the readers:
//! - *fields* (seed % 3 = 0): the file decoded, one to three of its fields changed through
//!   its serde tree (a number set to 0, 1, a neighbour, a huge or negative value; a list
//!   emptied, cut, reversed, or an element repeated or dropped), re-encoded by the format's
//!   writer: a well-formed file that says something wrong, for the structure checks, the
//!   merger, the player and the validator;
//! - *payload* (1): the decoded payload's bytes flipped, overwritten, cut or repeated, then
//!   wrapped in a correct container (checksum and lengths right), for the payload decoder;
//! - *container* (2): the file's bytes flipped or cut, for the container's own checks.
//!
//! The mutant is written whatever it is (a mutant that fails to encode is retried with the
//! next draw); the seed alone decides it, so a failure found is replayed by its seed.

use std::path::Path;
use std::process::ExitCode;

use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::Value;
use trisort_format::container::{decode, encode, encode_payload, FileKind};
use trisort_format::{Baked, Recording};

/// xorshift64*: a seeded stream, the same on every machine.
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in 0..n (n > 0).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// A new value for number `x`.
fn mutate_number(x: &serde_json::Number, rng: &mut Rng) -> Value {
    let f = x.as_f64().unwrap_or(0.0);
    let choices = [
        0.0,
        1.0,
        -1.0,
        f + 1.0,
        f - 1.0,
        f * 2.0,
        f * 1000.0,
        255.0,
        65_535.0,
        65_536.0,
        2_147_483_647.0,
        4_294_967_295.0,
        1e30,
        -1e30,
        1e-30,
    ];
    let v = choices[rng.below(choices.len())];
    if x.is_f64() {
        serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number)
    } else if v >= 0.0 && v.fract() == 0.0 && v <= u64::MAX as f64 {
        Value::from(v as u64)
    } else if v.fract() == 0.0 && v >= i64::MIN as f64 {
        Value::from(v as i64)
    } else {
        Value::from(v)
    }
}

/// Changes one place of `v`, reached by a random walk from the root: at a list it may stop
/// (and change the list) or go into an element; at a map into a field; at a leaf it changes
/// the leaf. `at` is the place's path (`/merge/strategy`, `/draws/7`), extended as the walk
/// goes; returns the path of the place changed.
fn mutate_tree(v: &mut Value, rng: &mut Rng, at: String) -> String {
    match v {
        Value::Object(map) if !map.is_empty() => {
            let k = rng.below(map.len());
            let key = map.keys().nth(k).cloned().expect("k < len");
            let at = format!("{at}/{key}");
            return mutate_tree(map.get_mut(&key).expect("present"), rng, at);
        }
        Value::Array(list) if !list.is_empty() && rng.below(3) > 0 => {
            let k = rng.below(list.len());
            return mutate_tree(&mut list[k], rng, format!("{at}/{k}"));
        }
        Value::Array(list) => match rng.below(5) {
            0 => list.clear(),
            1 => list.truncate(rng.below(list.len().max(1))),
            2 => list.reverse(),
            3 if !list.is_empty() => {
                let k = rng.below(list.len());
                let e = list[k].clone();
                let times = [1, 2, 100][rng.below(3)];
                for _ in 0..times {
                    list.insert(k, e.clone());
                }
            }
            _ if !list.is_empty() => {
                list.remove(rng.below(list.len()));
            }
            _ => {}
        },
        Value::Number(x) => *v = mutate_number(x, rng),
        Value::Bool(b) => *b = !*b,
        Value::String(s) => {
            *s = ["", "x", "auto", "visible", "hidden", "ignored", "Gl"][rng.below(7)].into()
        }
        Value::Null => *v = Value::from(rng.below(4)),
        Value::Object(_) => {}
    }
    at
}

/// A fields mutant of `value` (retried until one decodes as `T` again), and the paths of the
/// places changed.
fn fields<T: Serialize + DeserializeOwned>(value: &T, rng: &mut Rng) -> (T, Vec<String>) {
    let tree = serde_json::to_value(value).expect("trisort files serialize to a serde tree");
    for _ in 0..100 {
        let mut t = tree.clone();
        let changed: Vec<String> = (0..1 + rng.below(3))
            .map(|_| mutate_tree(&mut t, rng, String::new()))
            .collect();
        if let Ok(mutant) = serde_json::from_value::<T>(t) {
            return (mutant, changed);
        }
    }
    let same = serde_json::from_value(tree).expect("the unmutated tree decodes");
    (same, vec![])
}

/// `bytes` with a few flips, overwrites, cuts or repeats.
fn mutate_bytes(mut bytes: Vec<u8>, rng: &mut Rng) -> Vec<u8> {
    for _ in 0..1 + rng.below(4) {
        if bytes.is_empty() {
            break;
        }
        let at = rng.below(bytes.len());
        match rng.below(6) {
            0 => bytes[at] ^= 1 << rng.below(8),
            1 => bytes[at] = [0, 1, 0x7F, 0x80, 0xFF][rng.below(5)],
            2 => bytes.truncate(at),
            3 => {
                let end = (at + 1 + rng.below(64)).min(bytes.len());
                let chunk = bytes[at..end].to_vec();
                bytes.splice(at..at, chunk);
            }
            4 => {
                let end = (at + 1 + rng.below(64)).min(bytes.len());
                bytes.drain(at..end);
            }
            _ => bytes.insert(at, [0, 0xFF, 0x80][rng.below(3)]),
        }
    }
    bytes
}

fn mutant<T: Serialize + trisort_format::Stored>(
    kind: FileKind,
    input: &Path,
    seed: u64,
) -> Result<Vec<u8>, String> {
    let bytes = std::fs::read(input).map_err(|e| format!("{}: {e}", input.display()))?;
    let value: T = decode(kind, &bytes, input).map_err(|e| e.to_string())?;
    let mut rng = Rng::new(seed);
    Ok(match seed % 3 {
        0 => {
            let (mutant, changed) = fields(&value, &mut rng);
            // What changed, for whoever replays the seed.
            eprintln!("mutate: seed {seed}: fields {}", changed.join(", "));
            encode(kind, &mutant)
        }
        1 => {
            let raw = postcard::to_stdvec(&value).map_err(|e| e.to_string())?;
            encode_payload(kind, &mutate_bytes(raw, &mut rng))
        }
        _ => mutate_bytes(bytes, &mut rng),
    })
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [kind, input, output, seed] = &args[..] else {
        eprintln!("usage: mutate recording|baked IN OUT SEED");
        return ExitCode::from(2);
    };
    let Ok(seed) = seed.parse::<u64>() else {
        eprintln!("mutate: SEED must be a whole number, not {seed:?}");
        return ExitCode::from(2);
    };
    let input = Path::new(input);
    let bytes = match kind.as_str() {
        "recording" => mutant::<Recording>(FileKind::Recording, input, seed),
        "baked" => mutant::<Baked>(FileKind::Baked, input, seed),
        other => Err(format!("KIND is recording or baked, not {other:?}")),
    };
    match bytes.and_then(|b| std::fs::write(output, b).map_err(|e| format!("{output}: {e}"))) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("mutate: {e}");
            ExitCode::from(1)
        }
    }
}
