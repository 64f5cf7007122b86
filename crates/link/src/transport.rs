//! The bytes of a live link: the `mavlink` crate's connections for `udpout`, `tcpout` and
//! `serial`, and a UDP socket of aloft's own for `udpin`.
//!
//! # `udpin`: replies go to the vehicle
//!
//! A UDP listener has no peer: the `mavlink` crate's `udpin` answers whoever sent the last
//! datagram, so any host that can reach the port (a stray packet every half second, another
//! ground station, a scanner) took most of aloft's messages, its advice included. aloft owns
//! the socket instead: each datagram is read with its sender's address, its frames are parsed
//! from that datagram alone (a frame is never completed by another datagram, another sender's),
//! and every message carries the address it came from. [`crate::LinkSource`] sends to the
//! address of the vehicle's last HEARTBEAT (the vehicle as [`crate::Decoder`] decides it), and
//! to no one before it: whatever else arrives on the port changes nothing of where aloft's
//! messages go.

use std::io::ErrorKind;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::SyncSender;
use std::sync::Arc;
use std::time::{Duration, Instant};

use mavlink::dialects::ardupilotmega::MavMessage;
use mavlink::error::{MessageReadError, MessageWriteError};
use mavlink::{
    Connectable, Connection, ConnectionAddress, MAVLinkMessageRaw, MavConnection, MavHeader,
    MavlinkReader, MavlinkVersion, Message,
};

use crate::error::LinkError;

/// Read timeout of UDP sockets: how often the reading thread looks whether it should stop.
const READ_TIMEOUT: Duration = Duration::from_millis(100);

/// The largest UDP datagram (IPv4 payload), bytes.
const MAX_DATAGRAM: usize = 65_536;

/// A message the reading thread received, or how the link ended.
pub(crate) enum Incoming {
    /// A decoded message.
    Message {
        header: MavHeader,
        version: MavlinkVersion,
        message: Box<MavMessage>,
        at: Instant,
        /// The sender's address (`udpin` only).
        from: Option<SocketAddr>,
    },
    /// The link ended.
    Closed(std::io::Error),
}

/// Where the link's bytes go and come from.
#[derive(Clone)]
pub(crate) enum Transport {
    /// `udpout`, `tcpout`, `serial`: the `mavlink` crate's connection.
    Crate(Arc<Connection<MavMessage>>),
    /// `udpin`: aloft's own socket; sends go to an address given with each.
    UdpIn(Arc<UdpSocket>),
}

/// A link address checked to be one of the supported forms.
pub(crate) enum Address {
    /// `udpin:HOST:PORT`: the socket address to listen on.
    UdpIn(String),
    /// The others, as the `mavlink` crate takes them (UDP with a read timeout).
    Crate(ConnectionAddress),
}

impl Transport {
    /// Opens the link at `address`.
    pub(crate) fn open(address: Address) -> std::io::Result<Self> {
        match address {
            Address::UdpIn(at) => {
                let socket = UdpSocket::bind(at)?;
                socket.set_read_timeout(Some(READ_TIMEOUT))?;
                Ok(Self::UdpIn(Arc::new(socket)))
            }
            Address::Crate(a) => {
                let mut link = a.connect::<MavMessage>()?;
                link.set_allow_recv_any_version(true);
                Ok(Self::Crate(Arc::new(link)))
            }
        }
    }

    /// Sends one frame: on `udpin` to `to`, dropped without it. Whether it left (a full socket
    /// buffer drops it too).
    pub(crate) fn send(
        &self,
        raw: &MAVLinkMessageRaw,
        to: Option<SocketAddr>,
    ) -> std::io::Result<bool> {
        let result = match self {
            Self::Crate(link) => link.send_raw(raw).map(|_| ()).map_err(|e| match e {
                MessageWriteError::Io(e) => e,
                other => std::io::Error::other(other.to_string()),
            }),
            Self::UdpIn(socket) => match to {
                Some(to) => socket.send_to(raw_bytes(raw), to).map(|_| ()),
                None => return Ok(false),
            },
        };
        match result {
            Ok(()) => Ok(true),
            // No peer yet on the crate's UDP links, or a full socket buffer.
            Err(e) if transient(e.kind()) => Ok(false),
            Err(e) => Err(e),
        }
    }

    /// Reads the link into `tx` until it ends or `stop` is set (on the reading thread).
    pub(crate) fn read(&self, tx: &SyncSender<Incoming>, stop: &AtomicBool, undecoded: &AtomicU64) {
        match self {
            Self::Crate(link) => read_crate(link, tx, stop, undecoded),
            Self::UdpIn(socket) => read_udpin(socket, tx, stop, undecoded),
        }
    }
}

/// The bytes of a frame.
fn raw_bytes(raw: &MAVLinkMessageRaw) -> &[u8] {
    match raw {
        MAVLinkMessageRaw::V1(r) => r.raw_bytes(),
        MAVLinkMessageRaw::V2(r) => r.raw_bytes(),
    }
}

/// Errors after which a socket goes on: nothing to read yet, a full buffer, an interrupted call,
/// and a refused or reset peer (an ICMP answer to an earlier datagram, on some systems).
fn transient(kind: ErrorKind) -> bool {
    matches!(
        kind,
        ErrorKind::WouldBlock
            | ErrorKind::TimedOut
            | ErrorKind::Interrupted
            | ErrorKind::ConnectionRefused
            | ErrorKind::ConnectionReset
    )
}

/// The link address `url`, checked to be one of the supported forms.
pub(crate) fn parse_url(url: &str) -> Result<Address, LinkError> {
    let bad = || LinkError::Address {
        url: url.to_owned(),
    };
    let (scheme, rest) = url.split_once(':').ok_or_else(bad)?;
    let (host, port) = rest.rsplit_once(':').ok_or_else(bad)?;
    let supported = matches!(scheme, "udpin" | "udpout" | "tcpout" | "serial");
    if !supported || host.is_empty() || port.is_empty() {
        return Err(bad());
    }
    let numeric = port.parse::<u32>().is_ok();
    if !numeric {
        return Err(bad());
    }
    if scheme == "udpin" {
        port.parse::<u16>().map_err(|_| bad())?;
        return Ok(Address::UdpIn(rest.to_owned()));
    }
    match ConnectionAddress::parse_address(url).map_err(|_| bad())? {
        ConnectionAddress::Udp(c) => Ok(Address::Crate(ConnectionAddress::Udp(
            c.read_timeout(READ_TIMEOUT),
        ))),
        other => Ok(Address::Crate(other)),
    }
}

/// The message of a raw frame, with its header.
fn decoded(raw: &MAVLinkMessageRaw) -> Option<(MavHeader, MavlinkVersion, MavMessage)> {
    let version = raw.version();
    let message = MavMessage::parse(version, raw.message_id(), raw.payload()).ok()?;
    let header = MavHeader {
        system_id: raw.system_id(),
        component_id: raw.component_id(),
        sequence: raw.sequence(),
    };
    Some((header, version, message))
}

/// Hands one frame to the consumer (counted when the dialect refuses it); false once the
/// consumer is gone.
fn pass(
    raw: &MAVLinkMessageRaw,
    from: Option<SocketAddr>,
    tx: &SyncSender<Incoming>,
    undecoded: &AtomicU64,
) -> bool {
    let Some((header, version, message)) = decoded(raw) else {
        undecoded.fetch_add(1, Ordering::Relaxed);
        return true;
    };
    let incoming = Incoming::Message {
        header,
        version,
        message: Box::new(message),
        at: Instant::now(),
        from,
    };
    tx.send(incoming).is_ok()
}

/// Reads the crate's link until it ends or the source is dropped.
fn read_crate(
    link: &Connection<MavMessage>,
    tx: &SyncSender<Incoming>,
    stop: &AtomicBool,
    undecoded: &AtomicU64,
) {
    while !stop.load(Ordering::Relaxed) {
        match link.recv_raw() {
            Ok(raw) => {
                if !pass(&raw, None, tx, undecoded) {
                    return;
                }
            }
            Err(MessageReadError::Io(e)) if transient(e.kind()) => {}
            Err(MessageReadError::Io(e)) => {
                let _ = tx.send(Incoming::Closed(e));
                return;
            }
            Err(MessageReadError::Parse(_)) => {
                undecoded.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
}

/// Reads aloft's `udpin` socket until it fails or the source is dropped: each datagram's
/// frames with its sender's address.
fn read_udpin(
    socket: &UdpSocket,
    tx: &SyncSender<Incoming>,
    stop: &AtomicBool,
    undecoded: &AtomicU64,
) {
    let mut buf = vec![0u8; MAX_DATAGRAM];
    while !stop.load(Ordering::Relaxed) {
        match socket.recv_from(&mut buf) {
            Ok((n, from)) => {
                for raw in frames(&buf[..n]) {
                    if !pass(&raw, Some(from), tx, undecoded) {
                        return;
                    }
                }
            }
            Err(e) if transient(e.kind()) => {}
            Err(e) => {
                let _ = tx.send(Incoming::Closed(e));
                return;
            }
        }
    }
}

/// The CRC-valid frames (MAVLink 1 and 2) of one datagram, in order; bytes between them and a
/// frame cut by the datagram's end are passed over.
pub(crate) fn frames(datagram: &[u8]) -> impl Iterator<Item = MAVLinkMessageRaw> + '_ {
    let mut reader = MavlinkReader::with_capacity(datagram.len(), datagram);
    std::iter::from_fn(move || reader.read_any_raw_message::<MavMessage>().ok())
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::dialects::ardupilotmega::SYSTEM_TIME_DATA;
    use proptest::prelude::*;

    fn time(ms: u32) -> MavMessage {
        MavMessage::SYSTEM_TIME(SYSTEM_TIME_DATA {
            time_unix_usec: 0,
            time_boot_ms: ms,
        })
    }

    fn frame_bytes(v2: bool, ms: u32) -> Vec<u8> {
        let header = MavHeader {
            system_id: 1,
            component_id: 1,
            sequence: 0,
        };
        let mut out = Vec::new();
        match v2 {
            true => mavlink::write_v2_msg(&mut out, header, &time(ms)),
            false => mavlink::write_v1_msg(&mut out, header, &time(ms)),
        }
        .unwrap();
        out
    }

    #[test]
    fn a_datagram_yields_its_whole_frames_only() {
        let a = frame_bytes(true, 1);
        let b = frame_bytes(false, 2);
        let c = frame_bytes(true, 3);
        let mut damaged = frame_bytes(true, 4);
        damaged[12] ^= 0x01;
        let datagram = [&[0xFD, 0x00][..], &a, &[0x55; 7], &b, &damaged, &c, &a[..9]].concat();
        let got: Vec<MavMessage> = frames(&datagram).map(|r| decoded(&r).unwrap().2).collect();
        assert_eq!(got, [time(1), time(2), time(3)]);
        // A frame cut by the end of one datagram is not completed by the next.
        assert_eq!(frames(&a[9..]).count(), 0);
    }

    proptest! {
        /// Any bytes: no panic, and every frame found is CRC-valid (it decodes or is counted).
        #[test]
        fn any_datagram_is_framed_without_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
            for raw in frames(&bytes) {
                prop_assert!(raw_bytes(&raw).len() <= bytes.len());
            }
        }
    }
}
