//! A live link on the loopback interface: `LinkSource` listens on `udpin:127.0.0.1:PORT`; a
//! simulated vehicle on another UDP socket of 127.0.0.1 sends MAVLink 1 telemetry, answers the
//! mission download, and receives aloft's replies; then falls silent.
//!
//! aloft's requests and heartbeat come from its own ids (255, 190); its replies, which a ground
//! station displays, from the vehicle's system (1) and aloft's display component (191), as
//! QGroundControl takes only messages of the vehicle's system id.

use std::net::UdpSocket;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Sender};
use std::sync::Arc;
use std::time::{Duration, Instant};

use aloft_link::mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavFrame, MavMessage, MavModeFlag, MavSeverity, MavState, MavType,
    GLOBAL_POSITION_INT_DATA, HEARTBEAT_DATA, MISSION_COUNT_DATA, MISSION_ITEM_INT_DATA,
    PARAM_VALUE_DATA, SYS_STATUS_DATA,
};
use aloft_link::mavlink::{MavHeader, MavlinkReader, MavlinkVersion};
use aloft_link::{BatteryReply, Event, LinkOptions, LinkSource, Reply, Telemetry};

const VEHICLE: MavHeader = MavHeader {
    system_id: 1,
    component_id: 1,
    sequence: 0,
};

/// What the vehicle received from aloft.
type Received = (MavlinkVersion, MavHeader, MavMessage);

fn frame(msg: &MavMessage) -> Vec<u8> {
    let mut out = Vec::new();
    aloft_link::mavlink::write_v1_msg(&mut out, VEHICLE, msg).expect("serialise");
    out
}

fn telemetry() -> Vec<MavMessage> {
    vec![
        MavMessage::HEARTBEAT(HEARTBEAT_DATA {
            custom_mode: 3,
            mavtype: MavType::MAV_TYPE_QUADROTOR,
            autopilot: MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA,
            base_mode: MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED,
            system_status: MavState::MAV_STATE_ACTIVE,
            mavlink_version: 3,
        }),
        MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
            time_boot_ms: 10_000,
            lat: 473_977_000,
            lon: 85_456_000,
            alt: 500_000,
            relative_alt: 12_000,
            ..GLOBAL_POSITION_INT_DATA::default()
        }),
        MavMessage::SYS_STATUS(SYS_STATUS_DATA {
            voltage_battery: 15_200,
            current_battery: 1_250,
            battery_remaining: 80,
            ..SYS_STATUS_DATA::default()
        }),
    ]
}

/// The mission protocol's answers of the vehicle: MISSION_COUNT 2, then each item asked for.
fn answer(msg: &MavMessage) -> Option<MavMessage> {
    match msg {
        MavMessage::MISSION_REQUEST_LIST(_) => {
            Some(MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
                count: 2,
                target_system: 255,
                target_component: 190,
                ..MISSION_COUNT_DATA::default()
            }))
        }
        MavMessage::MISSION_REQUEST_INT(r) => {
            Some(MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA {
                seq: r.seq,
                frame: MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
                x: 473_977_000 + i32::from(r.seq) * 1_000,
                y: 85_456_000,
                z: 30.0,
                target_system: 255,
                target_component: 190,
                ..MISSION_ITEM_INT_DATA::default()
            }))
        }
        // The one failsafe parameter this vehicle answers (an INT8 would be cast as well).
        MavMessage::PARAM_REQUEST_READ(r) if r.param_id.to_str() == Ok("BATT_LOW_VOLT") => {
            Some(MavMessage::PARAM_VALUE(PARAM_VALUE_DATA {
                param_value: 10.5,
                param_count: 1_000,
                param_index: 42,
                param_id: "BATT_LOW_VOLT".into(),
                param_type: aloft_link::mavlink::dialects::ardupilotmega::MavParamType::MAV_PARAM_TYPE_REAL32,
            }))
        }
        _ => None,
    }
}

/// The vehicle: telemetry every 100 ms while `talking`, answers to aloft's requests, everything
/// received forwarded to the test.
fn vehicle(port: u16, talking: Arc<AtomicBool>, done: Arc<AtomicBool>, tx: Sender<Received>) {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("bind");
    socket.connect(("127.0.0.1", port)).expect("connect");
    socket
        .set_read_timeout(Some(Duration::from_millis(20)))
        .expect("timeout");
    let mut last_sent: Option<Instant> = None;
    let mut buf = [0u8; 2048];
    while !done.load(Ordering::Relaxed) {
        let due = last_sent.is_none_or(|t| t.elapsed() >= Duration::from_millis(100));
        if talking.load(Ordering::Relaxed) && due {
            last_sent = Some(Instant::now());
            for m in telemetry() {
                let _ = socket.send(&frame(&m));
            }
        }
        let Ok(n) = socket.recv(&mut buf) else {
            continue;
        };
        let mut reader = MavlinkReader::new(&buf[..n]);
        while let Ok(raw) = reader.read_any_raw_message::<MavMessage>() {
            let header = MavHeader {
                system_id: raw.system_id(),
                component_id: raw.component_id(),
                sequence: raw.sequence(),
            };
            let Ok(msg) = <MavMessage as aloft_link::mavlink::Message>::parse(
                raw.version(),
                raw.message_id(),
                raw.payload(),
            ) else {
                continue;
            };
            if let Some(a) = answer(&msg) {
                let _ = socket.send(&frame(&a));
            }
            let _ = tx.send((raw.version(), header, msg));
        }
    }
}

/// Events of the link until `stop` says so or 15 s pass.
fn events_until(link: &mut LinkSource, mut stop: impl FnMut(&Telemetry) -> bool) -> Vec<Telemetry> {
    let deadline = Instant::now() + Duration::from_secs(15);
    let mut out = Vec::new();
    while Instant::now() < deadline {
        let t = link.next_telemetry().expect("link up").expect("link open");
        let end = stop(&t);
        out.push(t);
        if end {
            return out;
        }
    }
    panic!("no such event in 15 s: {:?}", out.last());
}

#[test]
fn a_live_link_on_loopback_decodes_answers_and_reports_silence() {
    let port = {
        let probe = UdpSocket::bind("127.0.0.1:0").expect("bind");
        probe.local_addr().expect("address").port()
    };
    let options = LinkOptions {
        timeout: Duration::from_millis(600),
        ..LinkOptions::default()
    };
    let mut link = LinkSource::connect(&format!("udpin:127.0.0.1:{port}"), options).expect("udpin");
    let talking = Arc::new(AtomicBool::new(true));
    let done = Arc::new(AtomicBool::new(false));
    let (tx, rx) = channel();
    let sim = {
        let (talking, done) = (talking.clone(), done.clone());
        std::thread::spawn(move || vehicle(port, talking, done, tx))
    };

    // Telemetry: heartbeat, origin and position, battery.
    let mut seen = (false, false, false);
    let first = events_until(&mut link, |t| {
        match &t.event {
            Event::Heartbeat(h) => seen.0 = h.armed && h.mode == "AUTO",
            Event::Origin(o) => seen.1 = (o.lat_rad.to_degrees() - 47.3977).abs() < 1e-9,
            Event::Sample(s) => seen.2 |= s.voltage_v.is_some_and(|v| (v - 15.2).abs() < 1e-12),
            _ => {}
        }
        seen == (true, true, true)
    });
    assert_eq!(link.decoder().vehicle(), Some((1, 1)));

    // Replies, to the vehicle (the last sender on udpin).
    link.reply(&Reply::Value {
        name: "energy_remaining_wh",
        value: 42.5,
    })
    .expect("send");
    link.reply(&Reply::Text {
        text: "aloft: return now, 12 % margin left at home".into(),
        severity: aloft_link::Severity::Warning,
    })
    .expect("send");
    link.reply(&Reply::Battery(BatteryReply {
        id: 100,
        remaining_percent: Some(63.0),
        ..BatteryReply::default()
    }))
    .expect("send");

    // The failsafe parameter asked for and answered, then the mission, downloaded by aloft
    // START_AFTER the vehicle's first message.
    let low_volt = Event::Parameter {
        name: "BATT_LOW_VOLT".into(),
        value: 10.5,
    };
    if !first.iter().any(|t| t.event == low_volt) {
        events_until(&mut link, |t| t.event == low_volt);
    }
    let ev = events_until(&mut link, |t| matches!(t.event, Event::Mission(_)));
    let Some(Event::Mission(m)) = ev.last().map(|t| &t.event) else {
        unreachable!()
    };
    assert_eq!(m.len(), 2);
    assert!((m[1].params[4] - 47.3978).abs() < 1e-9);

    // Silence: LinkLost after the timeout, again after another one.
    talking.store(false, Ordering::Relaxed);
    let lost = events_until(&mut link, |t| matches!(t.event, Event::LinkLost { .. }));
    let Some(Event::LinkLost { silent_s }) = lost.last().map(|t| t.event.clone()) else {
        unreachable!()
    };
    assert!((0.6..1.5).contains(&silent_s), "{silent_s}");
    let again = link.next_telemetry().expect("link up").expect("open");
    assert!(matches!(again.event, Event::LinkLost { silent_s } if silent_s >= 1.2));
    assert_eq!(
        Duration::from_secs_f64(DISPLAY_HEARD_S),
        aloft_link::DISPLAY_HEARD
    );
    // Silent for longer than DISPLAY_HEARD: a reply now is not sent (from the vehicle's system
    // it would keep a ground station from saying the vehicle is gone).
    while link.next_telemetry().expect("link up").is_some_and(
        |t| !matches!(t.event, Event::LinkLost { silent_s } if silent_s > DISPLAY_HEARD_S),
    ) {}
    link.reply(&Reply::Text {
        text: SILENT_TEXT.into(),
        severity: aloft_link::Severity::Critical,
    })
    .expect("dropped, not an error");
    std::thread::sleep(Duration::from_millis(200));
    done.store(true, Ordering::Relaxed);
    sim.join().expect("vehicle thread");

    check_received(&rx.try_iter().collect::<Vec<Received>>());
    let stats = link.stats();
    assert!(
        stats.vehicle_messages > 10 && stats.undecoded == 0,
        "{stats:?}"
    );
}

/// aloft_link::DISPLAY_HEARD, s.
const DISPLAY_HEARD_S: f64 = 2.0;

/// A text replied once the vehicle has long been silent.
const SILENT_TEXT: &str = "aloft: said to a silent vehicle";

/// The messages a ground station displays.
fn displayed(m: &MavMessage) -> bool {
    matches!(
        m,
        MavMessage::NAMED_VALUE_FLOAT(_)
            | MavMessage::STATUSTEXT(_)
            | MavMessage::BATTERY_STATUS(_)
    )
}

/// What the vehicle received, in MAVLink 1 (the vehicle's version): the value, the text and the
/// battery replied from (1, 191), each with the next sequence of that sender; the mission
/// download and the ground station's heartbeat from (255, 190); nothing after the silence.
fn check_received(received: &[Received]) {
    assert!(received.iter().all(|(v, _, _)| *v == MavlinkVersion::V1));
    let ids = |h: &MavHeader| (h.system_id, h.component_id);
    let shown: Vec<&Received> = received.iter().filter(|(_, _, m)| displayed(m)).collect();
    assert_eq!(shown.len(), 3, "{shown:?}");
    for (k, (_, h, _)) in shown.iter().enumerate() {
        assert_eq!((ids(h), usize::from(h.sequence)), ((1, 191), k), "{h:?}");
    }
    assert!(received
        .iter()
        .filter(|(_, _, m)| !displayed(m))
        .all(|(_, h, _)| ids(h) == (255, 190)));
    let battery = received.iter().find_map(|(_, _, m)| match m {
        MavMessage::BATTERY_STATUS(b) => Some((b.id, b.battery_remaining)),
        _ => None,
    });
    assert_eq!(battery, Some((100, 63)));
    let value = received.iter().find_map(|(_, _, m)| match m {
        MavMessage::NAMED_VALUE_FLOAT(v) => Some(v.clone()),
        _ => None,
    });
    let value = value.expect("NAMED_VALUE_FLOAT");
    assert_eq!(value.name.to_str().unwrap(), "energy_rem");
    assert_eq!(value.value.to_bits(), 42.5f32.to_bits());
    let text = received.iter().find_map(|(_, _, m)| match m {
        MavMessage::STATUSTEXT(t) => Some(t.clone()),
        _ => None,
    });
    let text = text.expect("STATUSTEXT");
    assert!(!received.iter().any(
        |(_, _, m)| matches!(m, MavMessage::STATUSTEXT(t) if t.text.to_str() == Ok(SILENT_TEXT))
    ));
    assert_eq!(text.severity, MavSeverity::MAV_SEVERITY_WARNING);
    assert_eq!(
        text.text.to_str().unwrap(),
        "aloft: return now, 12 % margin left at home"
    );
    let names: Vec<&str> = received
        .iter()
        .map(|(_, _, m)| aloft_link::mavlink::Message::message_name(m))
        .filter(|n| n.starts_with("MISSION"))
        .collect();
    assert_eq!(
        names,
        [
            "MISSION_REQUEST_LIST",
            "MISSION_REQUEST_INT",
            "MISSION_REQUEST_INT",
            "MISSION_ACK"
        ]
    );
    assert!(received.iter().any(
        |(_, _, m)| matches!(m, MavMessage::HEARTBEAT(h) if h.mavtype == MavType::MAV_TYPE_GCS)
    ));
    // ArduPilot's failsafe parameters, each asked by name of the vehicle (1, 1).
    let asked: std::collections::BTreeSet<&str> = received
        .iter()
        .filter_map(|(_, _, m)| match m {
            MavMessage::PARAM_REQUEST_READ(r)
                if r.param_index == -1 && (r.target_system, r.target_component) == (1, 1) =>
            {
                r.param_id.to_str().ok()
            }
            _ => None,
        })
        .collect();
    let want = [
        "BATT_LOW_VOLT",
        "BATT_CRT_VOLT",
        "BATT_LOW_MAH",
        "BATT_CRT_MAH",
        "BATT_LOW_TIMER",
        "BATT_FS_VOLTSRC",
        "BATT_FS_LOW_ACT",
        "BATT_FS_CRT_ACT",
        "BATT_CAPACITY",
    ];
    assert_eq!(asked, want.into_iter().collect());
}

#[test]
fn a_tcp_link_that_cannot_connect_is_an_error_naming_it() {
    // Port 1 on loopback: nothing listens there.
    let e = LinkSource::connect("tcpout:127.0.0.1:1", LinkOptions::default()).err();
    let e = e.expect("refused").to_string();
    assert!(
        e.starts_with("tcpout:127.0.0.1:1: cannot open the link"),
        "{e}"
    );
}

/// A frame aloft sent: its (system, component) and message name.
type Sent = ((u32, u8), &'static str);

/// The frames in `socket` until it is quiet for 100 ms, but for heartbeats: (sender, name) each,
/// and the address they came from.
fn drain(socket: &UdpSocket) -> (Vec<Sent>, Option<std::net::SocketAddr>) {
    let (mut got, mut from) = (Vec::new(), None);
    let mut buf = [0u8; 2048];
    while let Ok((n, at)) = socket.recv_from(&mut buf) {
        from = Some(at);
        let mut reader = MavlinkReader::new(&buf[..n]);
        while let Ok(raw) = reader.read_any_raw_message::<MavMessage>() {
            let name = <MavMessage as aloft_link::mavlink::Message>::parse(
                raw.version(),
                raw.message_id(),
                raw.payload(),
            )
            .map(|m| aloft_link::mavlink::Message::message_name(&m))
            .expect("decodes");
            if name != "HEARTBEAT" {
                got.push(((raw.system_id(), raw.component_id()), name));
            }
        }
    }
    (got, from)
}

/// A PX4 takes a BATTERY_STATUS of its own system from another component as a battery of its
/// own, whose warning drives its battery failsafe (`MavlinkReceiver::handle_message_battery_status`):
/// to a PX4, aloft's battery goes from aloft's own ids (255, 190), its texts from (1, 191). On
/// `udpout`, where aloft has a peer from the start, no reply leaves before the vehicle is heard.
#[test]
fn alofts_battery_does_not_come_from_a_px4s_own_system() {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("bind");
    let port = socket.local_addr().expect("address").port();
    socket
        .set_read_timeout(Some(Duration::from_millis(100)))
        .expect("timeout");
    let options = LinkOptions {
        request_mission: false,
        request_parameters: false,
        ..LinkOptions::default()
    };
    let mut link =
        LinkSource::connect(&format!("udpout:127.0.0.1:{port}"), options).expect("udpout");
    let text = |t: &str| Reply::Text {
        text: t.into(),
        severity: aloft_link::Severity::Warning,
    };
    let battery = Reply::Battery(BatteryReply {
        id: 100,
        ..BatteryReply::default()
    });
    // aloft's heartbeat tells the vehicle where aloft is.
    let mut aloft = None;
    let deadline = Instant::now() + Duration::from_secs(10);
    while aloft.is_none() && Instant::now() < deadline {
        let _ = link.next_telemetry();
        link.reply(&text("aloft: before the vehicle"))
            .expect("dropped");
        link.reply(&battery).expect("dropped");
        let (got, from) = drain(&socket);
        assert_eq!(got, [], "sent before the vehicle was heard");
        aloft = from;
    }
    let aloft = aloft.expect("aloft's heartbeat");
    let px4 = MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        mavtype: MavType::MAV_TYPE_QUADROTOR,
        autopilot: MavAutopilot::MAV_AUTOPILOT_PX4,
        ..HEARTBEAT_DATA::default()
    });
    while link.decoder().vehicle().is_none() && Instant::now() < deadline {
        socket.send_to(&frame(&px4), aloft).expect("send");
        let _ = link.next_telemetry();
    }
    assert_eq!(link.decoder().vehicle(), Some((1, 1)));
    link.reply(&text("aloft: to a PX4")).expect("send");
    link.reply(&battery).expect("send");
    let (got, _) = drain(&socket);
    assert_eq!(
        got,
        [((1, 191), "STATUSTEXT"), ((255, 190), "BATTERY_STATUS")]
    );
}
