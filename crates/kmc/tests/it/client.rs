//! UartClient (async and blocking) against the chassis simulator.

use std::time::Duration;

use kmc::{BlockingUartClient, ChassisFrame, KmcError, SerialPortOptions, UartClient};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig, Fault};

#[test]
fn blocking_client_requests_and_writes() {
    let sim = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
    let mut client = BlockingUartClient::open(sim.path(), &SerialPortOptions::default()).unwrap();
    client.send_pc_control(0.5, 0.4).unwrap();
    client.write_speed_erpm(1, 1500.0).unwrap();
    client.write_servo_pulse_us(0, 1500.0).unwrap();
    client.request_all_state(1).unwrap();
    let Some(ChassisFrame::AllState(state)) = client.poll(Duration::from_secs(2)).unwrap() else {
        panic!("expected all-state");
    };
    assert_eq!((state.motor_id, state.id), (1, 2));
    let sim_state = sim.state();
    assert_eq!(sim_state.commanded_velocity_mps, 0.5);
    assert_eq!(sim_state.commanded_curvature_per_m, 0.4);
    assert_eq!(sim_state.speed_erpm[1], 1500.0);
    assert_eq!(sim_state.servo_pulse_us[0], 1500.0);
    client.system_reset(0).unwrap();
    client.request_battery_voltage(0).unwrap();
    assert!(matches!(client.poll(Duration::from_secs(2)).unwrap(), Some(ChassisFrame::BatteryVoltage(_))));
    assert_eq!(sim.stats().resets, 1);
    assert_eq!(sim.state().commanded_velocity_mps, 0.0, "reset stops the chassis");
    // Nothing pending: poll times out with None.
    assert_eq!(client.poll(Duration::from_millis(30)).unwrap(), None);
}

#[test]
fn non_finite_arguments_send_nothing() {
    let sim = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
    let mut client = BlockingUartClient::open(sim.path(), &SerialPortOptions::default()).unwrap();
    assert!(matches!(client.send_pc_control(f32::NAN, 0.0), Err(KmcError::Argument(_))));
    assert!(matches!(client.send_pc_control(0.0, f32::INFINITY), Err(KmcError::Argument(_))));
    assert!(matches!(client.write_speed_erpm(0, f32::NAN), Err(KmcError::Argument(_))));
    assert!(matches!(client.write_servo_pulse_us(0, f32::NEG_INFINITY), Err(KmcError::Argument(_))));
    assert_eq!(client.client_mut().counters().bytes_written, 0);
    // A valid command after the refused ones: once it has arrived, anything sent before it has.
    client.send_pc_control(0.1, 0.0).unwrap();
    robowire_fixtures::wait::until(Duration::from_secs(20), "the sentinel at the chassis", || {
        sim.stats().control_frames > 0
    });
    assert_eq!((sim.stats().control_frames, sim.stats().af_writes), (1, 0), "only the sentinel was sent");
    assert_eq!(sim.state().commanded_velocity_mps, 0.1);
}

#[test]
fn async_client_sees_dropped_responses_as_silence_and_hang_up_as_error() {
    let sim = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
    tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap().block_on(async {
        let mut client = UartClient::open(sim.path(), &SerialPortOptions::default()).unwrap();
        sim.inject(Fault::DropResponses { count: 1 });
        client.request_vehicle_speed().await.unwrap();
        assert_eq!(client.poll(Duration::from_millis(100)).await.unwrap(), None);
        client.request_vehicle_speed().await.unwrap();
        assert!(client.poll(Duration::from_secs(2)).await.unwrap().is_some());
        assert_eq!(sim.stats().responses_dropped, 1);
        sim.inject(Fault::HangUp);
        let err = client.poll(Duration::from_secs(2)).await.unwrap_err();
        assert!(matches!(err, KmcError::Link(_)), "{err}");
    });
}
