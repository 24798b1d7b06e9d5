//! How byte and word lists inside a plan ([`crate::Resource`] contents,
//! uniforms, noise tables) serialize: into a binary attachment beside the
//! message where the caller collects one ([`attach`], [`read_attached`]:
//! the GPU worker's pipe), else as base64 text. A small case's request
//! carries a 256 KiB noise table; as base64 inside JSON its encoding,
//! escaping and decoding were a third of vista's own time per case.

use std::cell::RefCell;

use base64::Engine;
use base64::engine::general_purpose::STANDARD;
use serde::{Deserialize, Deserializer, Serializer, de::Error};

thread_local! {
    /// Where serializing byte lists go, while [`attach`] runs.
    static OUT: RefCell<Option<Vec<u8>>> = const { RefCell::new(None) };
    /// What deserializing byte lists read, while [`read_attached`] runs.
    static IN: RefCell<Option<Vec<u8>>> = const { RefCell::new(None) };
}

/// Runs `f` (which serializes) with byte lists going into an attachment:
/// `f`'s result and the attachment.
pub fn attach<T>(f: impl FnOnce() -> T) -> (T, Vec<u8>) {
    let outer = OUT.with(|o| o.borrow_mut().replace(Vec::new()));
    let t = f();
    let bytes = OUT.with(|o| std::mem::replace(&mut *o.borrow_mut(), outer)).unwrap_or_default();
    (t, bytes)
}

/// Runs `f` (which deserializes) with `bytes` as the attachment that byte
/// lists refer to: `f`'s result, and `bytes` back.
pub fn read_attached<T>(bytes: Vec<u8>, f: impl FnOnce() -> T) -> (T, Vec<u8>) {
    let outer = IN.with(|i| i.borrow_mut().replace(bytes));
    let t = f();
    let bytes = IN.with(|i| std::mem::replace(&mut *i.borrow_mut(), outer)).unwrap_or_default();
    (t, bytes)
}

/// A byte list as serialized: base64 text, or `[offset, length]` in the
/// attachment.
#[derive(Deserialize)]
#[serde(untagged)]
enum Blob {
    Text(String),
    At([u64; 2]),
}

/// Serializes `len` bytes that `write` appends to a buffer.
fn put<S: Serializer>(len: usize, write: impl Fn(&mut Vec<u8>), s: S) -> Result<S::Ok, S::Error> {
    let at = OUT.with(|o| {
        o.borrow_mut().as_mut().map(|buf| {
            let at = buf.len() as u64;
            buf.reserve(len);
            write(buf);
            [at, len as u64]
        })
    });
    match at {
        Some(at) => s.collect_seq(at),
        None => {
            let mut bytes = Vec::with_capacity(len);
            write(&mut bytes);
            s.serialize_str(&STANDARD.encode(bytes))
        }
    }
}

fn get<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<u8>, D::Error> {
    match Blob::deserialize(d)? {
        Blob::Text(t) => STANDARD.decode(t).map_err(D::Error::custom),
        Blob::At([at, len]) => IN.with(|i| {
            let i = i.borrow();
            let bytes = i.as_deref().ok_or_else(|| D::Error::custom("a byte list in an attachment, but none came"))?;
            usize::try_from(at)
                .ok()
                .zip(usize::try_from(len).ok())
                .and_then(|(at, len)| bytes.get(at..at.checked_add(len)?))
                .map(<[u8]>::to_vec)
                .ok_or_else(|| {
                    D::Error::custom(format!("bytes {at}+{len} lie outside the {}-byte attachment", bytes.len()))
                })
        }),
    }
}

/// `#[serde(with = "wire::bytes")]` for `Vec<u8>`.
pub(crate) mod bytes {
    use super::*;

    pub fn serialize<S: Serializer>(v: &[u8], s: S) -> Result<S::Ok, S::Error> {
        put(v.len(), |buf| buf.extend_from_slice(v), s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<u8>, D::Error> {
        get(d)
    }
}

/// `#[serde(with = "wire::words")]` for `Vec<u32>` (little-endian bytes).
pub(crate) mod words {
    use super::*;

    pub fn serialize<S: Serializer>(v: &[u32], s: S) -> Result<S::Ok, S::Error> {
        let write = |buf: &mut Vec<u8>| {
            // A noise kernel's 256 KiB table per case: one copy, not 65,536.
            #[cfg(target_endian = "little")]
            buf.extend_from_slice(bytemuck::cast_slice(v));
            #[cfg(not(target_endian = "little"))]
            for w in v {
                buf.extend_from_slice(&w.to_le_bytes());
            }
        };
        put(4 * v.len(), write, s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<u32>, D::Error> {
        let bytes = get(d)?;
        if bytes.len() % 4 != 0 {
            return Err(D::Error::custom(format!("{} bytes are not whole u32 words", bytes.len())));
        }
        Ok(bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq, serde::Serialize, Deserialize)]
    struct Msg {
        #[serde(with = "bytes")]
        b: Vec<u8>,
        #[serde(with = "words")]
        w: Vec<u32>,
    }

    #[test]
    fn byte_lists_travel_as_text_or_in_an_attachment() {
        let msg = Msg { b: vec![1, 2, 3], w: vec![7, 0xDEAD_BEEF] };
        let text = serde_json::to_string(&msg).unwrap();
        assert_eq!(text, r#"{"b":"AQID","w":"BwAAAO++rd4="}"#);
        assert_eq!(serde_json::from_str::<Msg>(&text).unwrap(), msg);
        let (head, bytes) = attach(|| serde_json::to_string(&msg).unwrap());
        assert_eq!(head, r#"{"b":[0,3],"w":[3,8]}"#);
        assert_eq!(bytes, [1, 2, 3, 7, 0, 0, 0, 0xEF, 0xBE, 0xAD, 0xDE]);
        let (back, kept) = read_attached(bytes.clone(), || serde_json::from_str::<Msg>(&head).unwrap());
        assert_eq!((back, kept), (msg, bytes.clone()));
        // Outside the attachment, or with none, is an error, not a panic.
        let (e, _) = read_attached(bytes[..5].to_vec(), || serde_json::from_str::<Msg>(&head).unwrap_err());
        assert!(e.to_string().contains("bytes 3+8 lie outside the 5-byte attachment"), "{e}");
        assert!(serde_json::from_str::<Msg>(&head).is_err());
        // Nothing leaks into the next serialization.
        let msg = Msg { b: vec![1, 2, 3], w: vec![7, 0xDEAD_BEEF] };
        assert_eq!(serde_json::to_string(&msg).unwrap(), text);
    }
}
