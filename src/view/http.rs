//! The little HTTP/1.1 the viewer needs: one GET per connection, answered and closed.
//! No keep-alive, no chunking, no request bodies: the page is the only client, on the
//! same machine, and every answer is small enough to send whole (a 4K RGBA picture is
//! 33 MB, which the loopback carries in tens of milliseconds).
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::time::Duration;

/// The longest request head read: the page's requests are a few hundred bytes.
const MAX_HEAD: usize = 16 * 1024;

/// A parsed request: method, path (before `?`), query pairs (percent-decoded) and the
/// Host header.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Request {
    pub method: String,
    pub path: String,
    pub query: Vec<(String, String)>,
    pub host: Option<String>,
}

impl Request {
    /// Parses a request head (the request line and the headers). Errors say what was
    /// malformed, for a 400 answer.
    pub fn parse(head: &str) -> Result<Request, String> {
        let mut lines = head.split("\r\n");
        let line = lines.next().unwrap_or("");
        let mut parts = line.split(' ');
        let (Some(method), Some(target), Some(version), None) =
            (parts.next(), parts.next(), parts.next(), parts.next())
        else {
            return Err(format!(
                "expected a request line `METHOD /path HTTP/1.1`, got {line:?}"
            ));
        };
        if !version.starts_with("HTTP/1.") {
            return Err(format!("expected HTTP/1.0 or HTTP/1.1, got {version:?}"));
        }
        let (path, query) = target.split_once('?').unwrap_or((target, ""));
        let query = query
            .split('&')
            .filter(|p| !p.is_empty())
            .map(|p| {
                let (k, v) = p.split_once('=').unwrap_or((p, ""));
                Ok((percent_decode(k)?, percent_decode(v)?))
            })
            .collect::<Result<Vec<_>, String>>()?;
        let host = lines
            .filter_map(|h| h.split_once(':'))
            .find(|(k, _)| k.trim().eq_ignore_ascii_case("host"))
            .map(|(_, v)| v.trim().to_string());
        Ok(Request {
            method: method.to_string(),
            path: path.to_string(),
            query,
            host,
        })
    }

    /// The query value of `key`.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.query
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// `%XX` escapes and `+` (a space in a query) decoded; a bad escape or bytes that are
/// not UTF-8 are an error.
fn percent_decode(s: &str) -> Result<String, String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'%' => {
                let hex = s
                    .get(i + 1..i + 3)
                    .and_then(|h| u8::from_str_radix(h, 16).ok())
                    .ok_or_else(|| format!("bad percent escape in {s:?}"))?;
                out.push(hex);
                i += 3;
            }
            b'+' => {
                out.push(b' ');
                i += 1;
            }
            c => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8(out).map_err(|_| format!("{s:?} is not UTF-8 once decoded"))
}

/// An answer.
#[derive(Clone, Debug, PartialEq)]
pub struct Response {
    pub status: u16,
    pub content_type: &'static str,
    pub headers: Vec<(&'static str, String)>,
    pub body: Vec<u8>,
}

impl Response {
    pub fn ok(content_type: &'static str, body: Vec<u8>) -> Response {
        Response {
            status: 200,
            content_type,
            headers: Vec::new(),
            body,
        }
    }

    pub fn json(value: &serde_json::Value) -> Response {
        Response::ok("application/json", value.to_string().into_bytes())
    }

    /// An error with a one-line message as plain text.
    pub fn error(status: u16, message: impl Into<String>) -> Response {
        let mut body = message.into().into_bytes();
        body.push(b'\n');
        Response::ok("text/plain; charset=utf-8", body).with_status(status)
    }

    pub fn with_status(mut self, status: u16) -> Response {
        self.status = status;
        self
    }

    pub fn with_header(mut self, name: &'static str, value: String) -> Response {
        self.headers.push((name, value));
        self
    }

    fn reason(&self) -> &'static str {
        match self.status {
            200 => "OK",
            204 => "No Content",
            400 => "Bad Request",
            403 => "Forbidden",
            404 => "Not Found",
            405 => "Method Not Allowed",
            _ => "Error",
        }
    }

    /// The bytes on the wire. `no-store`: a render in progress changes under the same
    /// address; `nosniff`: the binary answers are never taken for script.
    pub fn write_to(&self, w: &mut impl Write) -> std::io::Result<()> {
        let mut head = format!(
            "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\n\
             Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n\
             Connection: close\r\n",
            self.status,
            self.reason(),
            self.content_type,
            self.body.len()
        );
        for (k, v) in &self.headers {
            head.push_str(&format!("{k}: {v}\r\n"));
        }
        head.push_str("\r\n");
        w.write_all(head.as_bytes())?;
        w.write_all(&self.body)?;
        w.flush()
    }
}

/// Reads one request from `stream`, answers it with `respond` and closes. A head that
/// is too long, malformed or not UTF-8 gets a 400.
pub fn handle(stream: TcpStream, respond: impl Fn(&Request) -> Response) {
    let _ = stream.set_read_timeout(Some(Duration::from_secs(30)));
    let mut reader = BufReader::new(&stream);
    let mut head = Vec::new();
    let answer = loop {
        let mut line = Vec::new();
        match (&mut reader)
            .take((MAX_HEAD + 1 - head.len()) as u64)
            .read_until(b'\n', &mut line)
        {
            Ok(0) | Err(_) => return,
            Ok(_) => {}
        }
        head.extend_from_slice(&line);
        if line == b"\r\n" || line == b"\n" {
            break match std::str::from_utf8(&head) {
                Ok(text) => match Request::parse(text.trim_end()) {
                    Ok(req) => respond(&req),
                    Err(e) => Response::error(400, e),
                },
                Err(_) => Response::error(400, "expected a UTF-8 request head"),
            };
        }
        if head.len() > MAX_HEAD {
            break Response::error(400, format!("request head longer than {MAX_HEAD} bytes"));
        }
    };
    let mut w = &stream;
    let _ = answer.write_to(&mut w);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_line_query_and_host_parse() {
        let r = Request::parse(
            "GET /api/image/0/view?view=ch3&ev=-1.5&mode=hue HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nAccept: */*",
        )
        .unwrap();
        assert_eq!(r.method, "GET");
        assert_eq!(r.path, "/api/image/0/view");
        assert_eq!(r.get("ev"), Some("-1.5"));
        assert_eq!(r.get("view"), Some("ch3"));
        assert_eq!(r.host.as_deref(), Some("127.0.0.1:8080"));
        let r = Request::parse("GET /x?a=%2e%2E+b HTTP/1.0").unwrap();
        assert_eq!(r.get("a"), Some(".. b"));
        assert!(Request::parse("GET /x?a=%zz HTTP/1.1").is_err());
        assert!(Request::parse("GET /x").is_err());
        assert!(Request::parse("GET /x SPDY/3").is_err());
    }
}
