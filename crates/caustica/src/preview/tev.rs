//! The network protocol of the tev image viewer, as far as a renderer needs it: create an image,
//! then update rectangles of it.
//!
//! One TCP connection from the renderer to tev, which only reads. Every packet is a
//! little-endian `u32` length that counts itself, then a type byte and the fields: booleans as
//! one byte, strings as UTF-8 ended by a NUL, integers and floats little-endian (tev's
//! `include/tev/Ipc.h`; pbrt-v4's `--display-server` speaks the same protocol).

use crate::error::{Error, Result};
use std::io::Write;
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

/// tev's default port.
pub const DEFAULT_PORT: u16 = 14158;

/// Packet types used here.
const CREATE_IMAGE: u8 = 4;
const UPDATE_IMAGE_V3: u8 = 6;

/// The names of the colour channels sent: tev shows R, G, B as a colour image.
pub const RGB: [&str; 3] = ["R", "G", "B"];

/// A packet being built: the length is filled in by [`Packet::finish`].
struct Packet(Vec<u8>);

impl Packet {
    fn new(kind: u8, capacity: usize) -> Packet {
        let mut bytes = Vec::with_capacity(capacity + 64);
        bytes.extend_from_slice(&[0; 4]);
        bytes.push(kind);
        Packet(bytes)
    }

    fn flag(&mut self, b: bool) -> &mut Packet {
        self.0.push(u8::from(b));
        self
    }

    fn text(&mut self, s: &str) -> &mut Packet {
        // A NUL would end the string early: names here never hold one, and are cut there if so.
        self.0.extend(s.bytes().take_while(|&b| b != 0));
        self.0.push(0);
        self
    }

    fn int(&mut self, v: i32) -> &mut Packet {
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }

    fn long(&mut self, v: i64) -> &mut Packet {
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }

    fn finish(mut self) -> Vec<u8> {
        let len = u32::try_from(self.0.len()).unwrap_or(u32::MAX);
        self.0[..4].copy_from_slice(&len.to_le_bytes());
        self.0
    }
}

/// Side lengths in the protocol are `i32`; images here are far smaller (at most 32768 a side).
fn side(v: usize) -> i32 {
    i32::try_from(v).unwrap_or(i32::MAX)
}

/// CreateImage: a black image `name` of `width × height` pixels with the channels `channels`
/// (sending it again replaces the image).
pub fn create_image(name: &str, width: usize, height: usize, channels: &[&str], grab_focus: bool) -> Vec<u8> {
    let mut p = Packet::new(CREATE_IMAGE, name.len() + 8 * channels.len());
    p.flag(grab_focus)
        .text(name)
        .int(side(width))
        .int(side(height))
        .int(side(channels.len()));
    for c in channels {
        p.text(c);
    }
    p.finish()
}

/// UpdateImage (version 3): the rectangle at column `x`, row `y` (from the top) of `width ×
/// height` pixels of image `name`, from `rgb`, interleaved R, G, B values with rows from the top.
pub fn update_rgb(name: &str, x: usize, y: usize, width: usize, height: usize, rgb: &[f32]) -> Vec<u8> {
    debug_assert_eq!(rgb.len(), width * height * 3);
    let mut p = Packet::new(UPDATE_IMAGE_V3, name.len() + 64 + rgb.len() * 4);
    p.flag(false).text(name).int(3);
    for c in RGB {
        p.text(c);
    }
    p.int(side(x)).int(side(y)).int(side(width)).int(side(height));
    // Each channel's first value and the step between its values, in floats.
    for offset in 0..3 {
        p.long(offset);
    }
    for _ in 0..3 {
        p.long(3);
    }
    for v in rgb {
        p.0.extend_from_slice(&v.to_le_bytes());
    }
    p.finish()
}

/// The address `--display` takes: `[HOST:]PORT`, with 127.0.0.1 (where tev listens by
/// default) when only a port is given; an IPv6 host in brackets (`[::1]:14158`).
pub fn parse_address(text: &str) -> Result<String> {
    let bad = || {
        Error::InvalidSettings(format!(
            "--display {text}: expected [HOST:]PORT, such as {DEFAULT_PORT} or 127.0.0.1:{DEFAULT_PORT}"
        ))
    };
    let (host, port) = match text.rsplit_once(':') {
        Some((host, port)) if !host.is_empty() && !host.ends_with(':') => (host, port),
        Some(_) => return Err(bad()),
        None => ("127.0.0.1", text),
    };
    let port: u16 = port.trim().parse().map_err(|_| bad())?;
    if port == 0 {
        return Err(bad());
    }
    Ok(format!("{host}:{port}"))
}

/// A connection to a tev viewer.
pub struct TevClient {
    stream: TcpStream,
}

/// How long connecting, and each write, may take before the viewer counts as gone.
const TIMEOUT: Duration = Duration::from_secs(3);

impl TevClient {
    /// Connects to `address` (`host:port`).
    pub fn connect(address: &str) -> std::io::Result<TevClient> {
        let mut last = None;
        for addr in address.to_socket_addrs()? {
            match TcpStream::connect_timeout(&addr, TIMEOUT) {
                Ok(stream) => {
                    stream.set_write_timeout(Some(TIMEOUT))?;
                    stream.set_nodelay(true)?;
                    return Ok(TevClient { stream });
                }
                Err(e) => last = Some(e),
            }
        }
        Err(last.unwrap_or_else(|| std::io::Error::other(format!("{address} names no address"))))
    }

    /// Sends one packet.
    pub fn send(&mut self, packet: &[u8]) -> std::io::Result<()> {
        self.stream.write_all(packet)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_one_pixel_update_has_the_documented_layout() {
        let packet = update_rgb("img", 2, 5, 1, 1, &[0.25, 0.5, 1.0]);
        // 4 length + 1 type + 1 focus + 4 name + 4 count + 6 channel names + 16 rectangle
        // + 24 offsets + 24 strides + 12 values.
        assert_eq!(packet.len(), 96);
        assert_eq!(&packet[..4], &96u32.to_le_bytes());
        assert_eq!(&packet[4..10], &[6, 0, b'i', b'm', b'g', 0]);
        assert_eq!(&packet[10..14], &3i32.to_le_bytes());
        assert_eq!(&packet[14..20], b"R\0G\0B\0");
        assert_eq!(&packet[20..24], &2i32.to_le_bytes());
        assert_eq!(&packet[24..28], &5i32.to_le_bytes());
        assert_eq!(&packet[36..44], &0i64.to_le_bytes());
        assert_eq!(&packet[52..60], &2i64.to_le_bytes());
        assert_eq!(&packet[60..68], &3i64.to_le_bytes());
        assert_eq!(&packet[84..88], &0.25f32.to_le_bytes());
        assert_eq!(&packet[92..96], &1.0f32.to_le_bytes());
    }

    #[test]
    fn create_image_lists_its_channels() {
        let packet = create_image("a.exr", 640, 480, &RGB, true);
        let mut expected = vec![4, 1];
        expected.extend_from_slice(b"a.exr\0");
        for v in [640i32, 480, 3] {
            expected.extend_from_slice(&v.to_le_bytes());
        }
        expected.extend_from_slice(b"R\0G\0B\0");
        assert_eq!(&packet[4..], &expected[..]);
        assert_eq!(packet.len(), 4 + expected.len());
    }

    #[test]
    fn addresses() {
        assert_eq!(parse_address("14158").unwrap(), "127.0.0.1:14158");
        assert_eq!(parse_address("viewer:9000").unwrap(), "viewer:9000");
        assert_eq!(parse_address("[::1]:14158").unwrap(), "[::1]:14158");
        for bad in ["", "host:", ":80", "x", "0", "70000", "a::"] {
            assert!(parse_address(bad).is_err(), "{bad}");
        }
    }
}
