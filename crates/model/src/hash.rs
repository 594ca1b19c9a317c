//! A small, stable, dependency-free hash (64-bit FNV-1a) for run ids, study fingerprints, the
//! experiment a run came from and the frames a sidecar vouches for. Not cryptographic: it only
//! has to be the same on every machine and every Rust version.

/// 64-bit FNV-1a of `bytes` (Fowler, Noll, Vo; offset basis 0xcbf29ce484222325, prime 0x100000001b3).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// `fnv1a64` as 16 lower-case hex digits.
pub fn hex64(bytes: &[u8]) -> String {
    format!("{:016x}", fnv1a64(bytes))
}

/// FNV-1a 64 over bytes given in pieces: `update(a); update(b)` is `fnv1a64(a ++ b)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fnv1a64(u64);

impl Default for Fnv1a64 {
    fn default() -> Self {
        Fnv1a64(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a64 {
    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    /// The hash as 16 lower-case hex digits (as [`hex64`]).
    pub fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }

    /// Add the bytes of file `path`, read in blocks.
    pub fn update_file(&mut self, path: &std::path::Path) -> std::io::Result<()> {
        use std::io::Read;
        let mut f = std::fs::File::open(path)?;
        let mut buf = vec![0u8; 1 << 16];
        loop {
            let n = f.read(&mut buf)?;
            if n == 0 {
                return Ok(());
            }
            self.update(&buf[..n]);
        }
    }
}

/// A writer that passes every byte on to `inner` and hashes it.
pub struct HashingWriter<'a, W: std::io::Write + ?Sized> {
    pub inner: &'a mut W,
    pub hash: &'a mut Fnv1a64,
}

impl<W: std::io::Write + ?Sized> std::io::Write for HashingWriter<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.hash.update(&buf[..n]);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_test_vectors() {
        // reference values of the FNV-1a 64 test suite (isthe.com/chongo/tech/comp/fnv)
        assert_eq!(fnv1a64(b""), 0xcbf29ce484222325);
        assert_eq!(fnv1a64(b"a"), 0xaf63dc4c8601ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x85944171f73967e8);
    }

    #[test]
    fn pieces_and_a_writer_hash_as_the_whole() {
        let mut h = Fnv1a64::default();
        h.update(b"foo");
        h.update(b"bar");
        assert_eq!(h.hex(), hex64(b"foobar"));
        let (mut out, mut h) = (Vec::new(), Fnv1a64::default());
        std::io::Write::write_all(
            &mut HashingWriter {
                inner: &mut out,
                hash: &mut h,
            },
            b"foobar",
        )
        .unwrap();
        assert_eq!(
            (out.as_slice(), h.hex()),
            (&b"foobar"[..], "85944171f73967e8".to_string())
        );
    }
}
