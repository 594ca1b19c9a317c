pub mod envelope_cases;
