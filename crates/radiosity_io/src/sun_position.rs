//! Where the sun is from a place and a time: the NOAA solar calculator's equations (after
//! Meeus, *Astronomical Algorithms*, 2nd ed., ch. 25 and 28: the sun's apparent longitude,
//! the obliquity of the ecliptic and the equation of time), good to about 0.01° in declination
//! and a few seconds of time between 1800 and 2100. Atmospheric refraction is left out (it
//! lifts the sun by under 0.1° above 10° of elevation).

use toml::value::Datetime;

/// The sun seen from a place at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SolarPosition {
    /// Height above the horizon, degrees.
    pub(crate) elevation: f64,
    /// Bearing from north towards east, degrees in [0, 360).
    pub(crate) azimuth: f64,
}

/// Why a date-time cannot place the sun.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum TimeError {
    /// A date without a time, or a time without a date.
    Incomplete,
    /// A local time without its offset from UTC (`+02:00`, `Z`): the hour would be a guess.
    NoOffset,
}

/// The Julian day of a TOML offset date-time (UTC), or why it is not one.
fn julian_day(t: &Datetime) -> Result<f64, TimeError> {
    let (Some(date), Some(time)) = (t.date, t.time) else { return Err(TimeError::Incomplete) };
    let offset_minutes = match t.offset {
        Some(toml::value::Offset::Z) => 0,
        Some(toml::value::Offset::Custom { minutes }) => i32::from(minutes),
        None => return Err(TimeError::NoOffset),
    };
    let (mut y, mut m) = (i32::from(date.year), i32::from(date.month));
    if m <= 2 {
        y -= 1;
        m += 12;
    }
    // Meeus (7.1), Gregorian calendar.
    let a = y.div_euclid(100);
    let b = 2 - a + a.div_euclid(4);
    let day = f64::from(date.day)
        + (f64::from(time.hour) * 60.0 + f64::from(time.minute) - f64::from(offset_minutes)
            + (f64::from(time.second.unwrap_or(0)) + f64::from(time.nanosecond.unwrap_or(0)) * 1e-9) / 60.0)
            / 1440.0;
    Ok((365.25 * f64::from(y + 4716)).floor() + (30.6001 * f64::from(m + 1)).floor() + day + f64::from(b)
        - 1524.5)
}

/// The sun at `time` seen from `latitude` (degrees north) and `longitude` (degrees east).
pub(crate) fn solar_position(
    latitude: f64,
    longitude: f64,
    time: &Datetime,
) -> Result<SolarPosition, TimeError> {
    let jd = julian_day(time)?;
    let t = (jd - 2_451_545.0) / 36_525.0;
    let (sin, cos) = (|d: f64| d.to_radians().sin(), |d: f64| d.to_radians().cos());
    // The sun's geometric mean longitude and mean anomaly, the orbit's eccentricity (Meeus 25.2–25.4).
    let l0 = (280.466_46 + t * (36_000.769_83 + 0.000_303_2 * t)).rem_euclid(360.0);
    let m = 357.529_11 + t * (35_999.050_29 - 0.000_153_7 * t);
    let e = 0.016_708_634 - t * (0.000_042_037 + 0.000_000_126_7 * t);
    // Equation of the centre, apparent longitude (nutation and aberration, 25.8).
    let c = sin(m) * (1.914_602 - t * (0.004_817 + 0.000_014 * t))
        + sin(2.0 * m) * (0.019_993 - 0.000_101 * t)
        + sin(3.0 * m) * 0.000_289;
    let omega = 125.04 - 1_934.136 * t;
    let lambda = l0 + c - 0.005_69 - 0.004_78 * sin(omega);
    // Obliquity of the ecliptic, corrected (22.2, 25.8), and the declination (25.7).
    let eps0 = 23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.000_59 - t * 0.001_813))) / 60.0) / 60.0;
    let eps = eps0 + 0.002_56 * cos(omega);
    let declination = (sin(eps) * sin(lambda)).asin().to_degrees();
    // Equation of time, minutes (28.3).
    let y = (eps.to_radians() / 2.0).tan().powi(2);
    let eot = 4.0
        * (y * sin(2.0 * l0) - 2.0 * e * sin(m) + 4.0 * e * y * sin(m) * cos(2.0 * l0)
            - 0.5 * y * y * sin(4.0 * l0)
            - 1.25 * e * e * sin(2.0 * m))
        .to_degrees();
    // True solar time from UTC, then the hour angle (0 at solar noon).
    let utc_minutes = (jd + 0.5).fract() * 1440.0;
    let solar_minutes = (utc_minutes + eot + 4.0 * longitude).rem_euclid(1440.0);
    let hour_angle = solar_minutes / 4.0 - 180.0;
    let cos_zenith = (sin(latitude) * sin(declination) + cos(latitude) * cos(declination) * cos(hour_angle))
        .clamp(-1.0, 1.0);
    let elevation = 90.0 - cos_zenith.acos().to_degrees();
    // Bearing from north through east: atan2 of the east and north parts of the direction.
    let east = -cos(declination) * sin(hour_angle);
    let north = sin(declination) * cos(latitude) - cos(declination) * cos(hour_angle) * sin(latitude);
    let azimuth = east.atan2(north).to_degrees().rem_euclid(360.0);
    Ok(SolarPosition { elevation, azimuth })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(s: &str) -> Datetime {
        s.parse().unwrap()
    }

    /// Meeus example 7.a: 1957 October 4.81 is JD 2436116.31.
    #[test]
    fn julian_days_follow_meeus() {
        let jd = julian_day(&at("1957-10-04T19:26:24Z")).unwrap();
        assert!((jd - 2_436_116.31).abs() < 1e-6, "{jd}");
        let noon = julian_day(&at("2000-01-01T12:00:00Z")).unwrap();
        assert!((noon - 2_451_545.0).abs() < 1e-9);
        // The same instant written with an offset.
        assert_eq!(julian_day(&at("2000-01-01T14:00:00+02:00")).unwrap(), noon);
    }

    /// At the June solstice's solar noon the sun stands 90° − φ + 23.44° above the horizon,
    /// due south north of the tropic; at the March equinox's it is overhead at the equator.
    /// Solar noon at Greenwich on 2026-06-21 falls at 12:01:50 UTC (the equation of time is
    /// −1.8 min): within 0.05° of elevation and 0.5° of azimuth.
    #[test]
    fn the_sun_stands_where_the_seasons_put_it() {
        let p = solar_position(51.4779, 0.0, &at("2026-06-21T12:01:50Z")).unwrap();
        assert!((p.elevation - (90.0 - 51.4779 + 23.437)).abs() < 0.05, "{p:?}");
        assert!((p.azimuth - 180.0).abs() < 0.5, "{p:?}");
        // The 2026 March equinox is at 14:46 UTC; solar noon there is at longitude −41.7°.
        let q = solar_position(0.0, -41.7 + 1.9, &at("2026-03-20T14:46:00Z")).unwrap();
        assert!(q.elevation > 89.5, "{q:?}");
        // Paris the morning after the September equinox: the sun rises at 07:35 local time,
        // due east; at 07:00 it is below the horizon, at 09:00 low in the east.
        let before = solar_position(48.85, 2.35, &at("2026-09-23T07:00:00+02:00")).unwrap();
        assert!(before.elevation < 0.0, "{before:?}");
        let r = solar_position(48.85, 2.35, &at("2026-09-23T09:00:00+02:00")).unwrap();
        assert!(r.elevation > 5.0 && r.elevation < 20.0 && (r.azimuth - 100.0).abs() < 15.0, "{r:?}");
    }

    #[test]
    fn a_time_without_offset_or_date_is_refused() {
        assert_eq!(solar_position(0.0, 0.0, &at("2026-06-21T12:00:00")), Err(TimeError::NoOffset));
        assert_eq!(solar_position(0.0, 0.0, &at("2026-06-21")), Err(TimeError::Incomplete));
    }
}
