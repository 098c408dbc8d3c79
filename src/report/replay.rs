//! The replay's data: decimated trajectories packed compactly for the page.
//!
//! About [`MAX_FRAMES`] frames are kept (every k-th recorded time, k = ⌈times / MAX_FRAMES⌉,
//! and the last). Positions are
//! quantised to 1 cm and each agent's coordinates are delta-encoded from its previous frame;
//! a frame holds, per agent in id order, `zigzag(dx) · 4 + state` and `zigzag(dy)` as LEB128
//! varints (a walking agent moves a few decimetres between frames, so most values take one
//! or two bytes), and the byte stream is base64-encoded into the page. The page's script
//! inverts exactly these steps. Cost: O(frames × agents) time and output.

use super::data::Sample;
use std::collections::BTreeMap;

/// Most frames the page embeds (default: `600`; 20 s of replay at 30 frames/s).
pub const MAX_FRAMES: usize = 600;

/// Quantisation step of the positions, metres (default: `0.01`).
pub const QUANTUM: f64 = 0.01;

/// The packed replay.
#[derive(Debug, Clone, PartialEq)]
pub struct Replay {
    /// Agent ids, in the order of each frame's records.
    pub agents: Vec<u32>,
    /// Time of each frame, seconds.
    pub times: Vec<f64>,
    /// The varint stream, base64.
    pub data: String,
}

/// Encodes `samples` (sorted by time, then agent). An agent missing from a recorded time
/// keeps its last position and state. `None` when there is nothing to replay.
pub fn encode(samples: &[Sample]) -> Option<Replay> {
    let agents: Vec<u32> = {
        let mut a: Vec<u32> = samples.iter().map(|s| s.agent).collect();
        a.sort_unstable();
        a.dedup();
        a
    };
    if agents.is_empty() {
        return None;
    }
    let slot: BTreeMap<u32, usize> = agents.iter().enumerate().map(|(k, &a)| (a, k)).collect();
    // Group by recorded time.
    let mut groups: Vec<(f64, &[Sample])> = Vec::new();
    let mut start = 0;
    for k in 1..=samples.len() {
        if k == samples.len() || samples[k].time != samples[start].time {
            groups.push((samples[start].time, &samples[start..k]));
            start = k;
        }
    }
    let stride = groups.len().div_ceil(MAX_FRAMES).max(1);
    let mut current: Vec<(i64, i64, u8)> = vec![(0, 0, 0); agents.len()];
    let mut previous = current.clone();
    let mut bytes = Vec::new();
    let mut times = Vec::new();
    for (g, (t, rows)) in groups.iter().enumerate() {
        for s in *rows {
            if let Some(&k) = slot.get(&s.agent) {
                let q = |v: f64| (v / QUANTUM).round() as i64;
                current[k] = (q(s.x), q(s.y), s.state & 3);
            }
        }
        // Keep every stride-th time and always the last one.
        if g % stride != 0 && g + 1 != groups.len() {
            continue;
        }
        times.push(*t);
        for (now, before) in current.iter().zip(previous.iter_mut()) {
            varint(&mut bytes, zigzag(now.0 - before.0) * 4 + u64::from(now.2));
            varint(&mut bytes, zigzag(now.1 - before.1));
            *before = *now;
        }
    }
    Some(Replay {
        agents,
        times,
        data: base64(&bytes),
    })
}

fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

fn varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8 & 0x7f) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// Standard base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                s.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Independent decoder: the inverse of every step, as the page's script does it.
    fn decode(r: &Replay) -> Vec<Vec<(i64, i64, u8)>> {
        let table: Vec<u8> =
            b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/".to_vec();
        let mut bits = 0u32;
        let mut nbits = 0;
        let mut bytes = Vec::new();
        for c in r.data.bytes().filter(|&c| c != b'=') {
            let v = table.iter().position(|&t| t == c).unwrap() as u32;
            bits = (bits << 6) | v;
            nbits += 6;
            if nbits >= 8 {
                nbits -= 8;
                bytes.push((bits >> nbits) as u8);
                bits &= (1 << nbits) - 1;
            }
        }
        let mut pos = 0;
        let mut next = || {
            let (mut v, mut shift) = (0u64, 0);
            loop {
                let b = bytes[pos];
                pos += 1;
                v |= u64::from(b & 0x7f) << shift;
                shift += 7;
                if b < 0x80 {
                    return v;
                }
            }
        };
        let unzig = |v: u64| (v >> 1) as i64 ^ -((v & 1) as i64);
        let mut cur = vec![(0i64, 0i64, 0u8); r.agents.len()];
        let mut frames = Vec::new();
        for _ in &r.times {
            for c in cur.iter_mut() {
                let a = next();
                let b = next();
                c.0 += unzig(a >> 2);
                c.2 = (a & 3) as u8;
                c.1 += unzig(b);
            }
            frames.push(cur.clone());
        }
        frames
    }

    fn sample(time: f64, agent: u32, x: f64, y: f64, state: u8) -> Sample {
        Sample {
            time,
            agent,
            x,
            y,
            state,
        }
    }

    #[test]
    fn base64_matches_rfc4648_vectors() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }

    #[test]
    fn round_trips_positions_to_the_centimetre_with_states() {
        let s = vec![
            sample(0.0, 0, 1.234, 5.0, 0),
            sample(0.0, 3, 29.99, 0.004, 2),
            sample(1.0, 0, 0.5, 4.0, 1),
            sample(1.0, 3, 30.0, 9.996, 3),
        ];
        let r = encode(&s).unwrap();
        assert_eq!(r.agents, vec![0, 3]);
        assert_eq!(r.times, vec![0.0, 1.0]);
        let f = decode(&r);
        assert_eq!(f[0], vec![(123, 500, 0), (2999, 0, 2)]);
        assert_eq!(f[1], vec![(50, 400, 1), (3000, 1000, 3)]);
    }

    #[test]
    fn decimates_to_at_most_max_frames_keeping_the_last() {
        let n = 3 * MAX_FRAMES + 7;
        let s: Vec<Sample> = (0..n)
            .map(|k| sample(k as f64, 1, k as f64 * 0.01, 0.0, 0))
            .collect();
        let r = encode(&s).unwrap();
        assert!(r.times.len() <= MAX_FRAMES + 1, "{}", r.times.len());
        assert_eq!(*r.times.last().unwrap(), (n - 1) as f64);
        let f = decode(&r);
        for (t, frame) in r.times.iter().zip(&f) {
            assert_eq!(frame[0].0, *t as i64, "x in cm equals the time index");
        }
    }

    #[test]
    fn a_missing_agent_keeps_its_last_position() {
        let s = vec![
            sample(0.0, 0, 1.0, 1.0, 0),
            sample(0.0, 1, 2.0, 2.0, 2),
            sample(1.0, 0, 1.5, 1.0, 0),
        ];
        let f = decode(&encode(&s).unwrap());
        assert_eq!(f[1][1], (200, 200, 2));
        assert!(encode(&[]).is_none());
    }
}
