//! The floor under `ros2_latency`: what two thread wake-ups and a loopback datagram cost on this
//! machine with nothing else in the way. As in publishing, a caller wakes a sending thread
//! (here through a socket pair, as RustDDS's event loop is woken), which sends a UDP datagram on
//! loopback; a receiving thread blocked on it (as Cyclone's receive thread) stores its stamp,
//! and a spinning poller (as the benchmark's polling subscriber) finds it. One stamp per
//! millisecond, 5,000 of them; prints median, P99 and maximum of caller -> poller.
//!
//! `cargo bench -p evtac-online --bench wake_floor`

use std::io::{Read, Write};
use std::net::UdpSocket;
use std::os::unix::net::UnixStream;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

fn wall_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

const STAMPS: usize = 5000;

fn main() {
    let receiver = UdpSocket::bind("127.0.0.1:0").expect("bind");
    let to = receiver.local_addr().expect("address");
    let arrived = Arc::new(AtomicU64::new(0));
    std::thread::spawn({
        let arrived = Arc::clone(&arrived);
        move || {
            let mut buf = [0u8; 8];
            while receiver.recv(&mut buf).is_ok() {
                arrived.store(u64::from_le_bytes(buf), Ordering::Release);
            }
        }
    });
    let (mut doorbell, mut ringing) = UnixStream::pair().expect("socket pair");
    let stamp = Arc::new(AtomicU64::new(0));
    std::thread::spawn({
        let stamp = Arc::clone(&stamp);
        move || {
            let sender = UdpSocket::bind("127.0.0.1:0").expect("bind");
            let mut byte = [0u8; 1];
            while ringing.read(&mut byte).is_ok_and(|n| n == 1) {
                let _ = sender.send_to(&stamp.load(Ordering::Acquire).to_le_bytes(), to);
            }
        }
    });
    std::thread::spawn(move || {
        for _ in 0..STAMPS + 100 {
            std::thread::sleep(Duration::from_millis(1));
            stamp.store(wall_ns(), Ordering::Release);
            if doorbell.write_all(&[1]).is_err() {
                return;
            }
        }
    });
    let (mut last, mut added) = (0, Vec::with_capacity(STAMPS));
    while added.len() < STAMPS {
        let sent = arrived.load(Ordering::Acquire);
        if sent != last {
            last = sent;
            added.push(wall_ns().saturating_sub(sent));
        }
    }
    added.sort_unstable();
    let at = |q: f64| added[((added.len() - 1) as f64 * q) as usize] as f64 / 1000.0;
    println!(
        "two wake-ups and a loopback datagram, {STAMPS} at 1 ms: median {:.0} us, P99 {:.0} us, \
         max {:.0} us",
        at(0.5),
        at(0.99),
        at(1.0)
    );
}
